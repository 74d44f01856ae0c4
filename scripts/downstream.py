#!/usr/bin/env python3
"""Every Rust code block of the docs compiles and runs in a crate that depends on `aemstep` alone.

Usage (from anywhere; paths are relative to the repository root):

  python3 scripts/downstream.py              check every block (a stage of scripts/test.sh)
  python3 scripts/downstream.py --self-test  show that broken blocks fail the check
  options: --keep (keep the generated project and print its path),
           --target-dir DIR (default: $CARGO_TARGET_DIR/downstream-check, else
           <repo>/target/downstream-check; shared between runs, so only what changed is rebuilt)

Why: the crate's own doctests compile with the crate's dev-dependencies in scope, so a
block that names `nalgebra::…` (or uses nalgebra's `matrix!`, which expands to `nalgebra::…`)
passes them and fails for a user, whose only dependency is `aemstep`.

What it checks: the code blocks of README.md, docs/*.md and the rustdoc of src/ (`///` and
`//!` comments). A block is Rust the way rustdoc decides it (no language, `rust`, or only
rustdoc's own attributes). Each block is made into a program the way rustdoc makes a doctest:
hidden `# ` lines are kept (without their `# `), `#![…]` lines go to the crate top, a block
without `fn main` is wrapped in one (with rustdoc's `Result` wrapper when it ends in `(())`).
All of them go into ONE fresh cargo project under /tmp (outside the repository) whose only
dependency is `aemstep = { path = <repo>, features = ["std"] }` — every block gets `std`, the
host-only feature, since the programs run on the host anyway — one `[[bin]]` per block named
after its file and line, and the repository's Cargo.lock (the same dependency versions).
One `cargo build --keep-going` builds them all (aemstep once); then each block runs:

  - plain blocks must build and exit 0;
  - `no_run` blocks must build;
  - `should_panic` blocks must build and panic (exit status 101);
  - `compile_fail` blocks are `[[example]]`s, built one by one, and must FAIL to compile;
  - `ignore` blocks are not compiled; each must say why in its first line, a comment
    `// Not compiled: <reason>`. Firmware fragments (`#[exception]` handlers, `#![no_main]`
    programs, cortex-m crates) are such blocks: they cannot be host programs, and the whole
    firmware they are cut from is built and run under QEMU by scripts/qemu.sh.

It fails listing the file:line (the opening fence) of every block that fails, and prints the
number of blocks checked.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

# rustdoc's own code-block attributes (src/librustdoc/html/markdown.rs, LangString::parse).
RUSTDOC_ATTRS = {"rust", "ignore", "should_panic", "no_run", "compile_fail", "test_harness",
                 "standalone_crate", "allow_fail"}
FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*(.*?)\s*$")
DOC_LINE = re.compile(r"^\s*(///|//!)(?!/)(.*)$")
IGNORE_REASON = "// Not compiled:"
RUN_TIMEOUT = 300


class Block:
    def __init__(self, path, line, attrs, code):
        self.path, self.line, self.attrs, self.code = path, line, attrs, code

    @property
    def where(self):
        return f"{self.path}:{self.line}"

    @property
    def name(self):
        stem = re.sub(r"[^A-Za-z0-9]+", "_", self.path.replace(".rs", "").replace(".md", ""))
        return f"{stem.strip('_').lower()}_{self.line}"

    @property
    def mode(self):
        for a in ("ignore", "compile_fail", "should_panic", "no_run"):
            if a in self.attrs or (a == "ignore" and any(t.startswith("ignore-") for t in self.attrs)):
                return a
        return "run"


def rust_attrs(info):
    """The block's attributes if rustdoc would treat it as Rust, else None."""
    tokens = [t for t in re.split(r"[\s,]+", info.strip("{} ")) if t]
    seen_rust = seen_other = False
    for t in tokens:
        if t in RUSTDOC_ATTRS or re.fullmatch(r"edition\d{4}|ignore-.+|E\d{4}", t):
            seen_rust = True
        else:
            seen_other = True
    return tokens if (seen_rust or not seen_other) else None


def fenced_blocks(lines, path):
    """Code blocks in markdown `lines` [(line number, text)]."""
    out, i = [], 0
    while i < len(lines):
        lineno, text = lines[i]
        m = FENCE.match(text)
        if not m:
            i += 1
            continue
        indent, fence, info = m.groups()
        body, j = [], i + 1
        while j < len(lines):
            t = lines[j][1]
            s = t.strip()
            if s.startswith(fence[0] * len(fence)) and set(s) == {fence[0]}:
                break
            # Indented fences (in lists) indent their content too.
            body.append(t[len(indent):] if t.startswith(indent) else t.lstrip())
            j += 1
        attrs = rust_attrs(info)
        if attrs is not None:
            out.append(Block(path, lineno, attrs, body))
        i = j + 1
    return out


def extract(root):
    blocks = []
    md = ["README.md"] + sorted(
        os.path.join("docs", f) for f in os.listdir(os.path.join(root, "docs")) if f.endswith(".md"))
    for rel in md:
        with open(os.path.join(root, rel), encoding="utf-8") as f:
            lines = list(enumerate(f.read().split("\n"), 1))
        blocks += fenced_blocks(lines, rel)
    for dirpath, _, files in sorted(os.walk(os.path.join(root, "src"))):
        for fn in sorted(files):
            if not fn.endswith(".rs"):
                continue
            path = os.path.join(dirpath, fn)
            rel = os.path.relpath(path, root)
            with open(path, encoding="utf-8") as f:
                src = f.read().split("\n")
            run, kind = [], None  # consecutive doc lines of one kind form one doc text
            for n, text in enumerate(src + [""], 1):
                m = DOC_LINE.match(text)
                if run and (not m or m.group(1) != kind):
                    blocks += fenced_blocks(run, rel)
                    run = []
                if m:
                    body = m.group(2)
                    run.append((n, body[1:] if body.startswith(" ") else body))
                    kind = m.group(1)
    return blocks


def doctest_source(block):
    """The program rustdoc would make of the block (src/librustdoc/doctest/make.rs)."""
    code = []
    for line in block.code:
        t = line.lstrip()
        if t == "#":
            code.append("")
        elif t.startswith("##"):
            code.append(line.replace("##", "#", 1))
        elif t.startswith("# "):
            code.append(line.replace("# ", "", 1))
        else:
            code.append(line)
    crate_attrs = [l for l in code if l.lstrip().startswith("#![")]
    body = "\n".join(l for l in code if not l.lstrip().startswith("#!["))
    head = f"// {block.where} ({', '.join(block.attrs) or 'rust'})\n#![allow(unused)]\n"
    head += "".join(a + "\n" for a in crate_attrs)
    if re.search(r"\bfn\s+main\s*\(", body):
        return head + body + "\n"
    if body.rstrip().endswith("(())"):
        return (head + "fn main() { fn _inner() -> core::result::Result<(), impl core::fmt::Debug> {\n"
                + body + "\n} _inner().unwrap() }\n")
    return head + "fn main() {\n" + body + "\n}\n"


def default_target_dir(root):
    env = os.environ.get("CARGO_TARGET_DIR")
    return os.path.join(env, "downstream-check") if env else os.path.join(root, "target", "downstream-check")


def cargo_json(args, cwd, target_dir):
    """Runs cargo with JSON messages: (return code, {target: [rendered errors]}, {bin: exe})."""
    proc = subprocess.run(["cargo"] + args + ["--message-format=json-diagnostic-rendered-ansi",
                                                "--target-dir", target_dir],
                          cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    errors, exes = {}, {}
    for line in proc.stdout.splitlines():
        try:
            msg = json.loads(line)
        except ValueError:
            continue
        if msg.get("reason") == "compiler-message" and msg["message"]["level"] in ("error", "error: internal compiler error"):
            name = msg["target"]["name"]
            errors.setdefault(name, []).append(re.sub(r"\x1b\[[0-9;]*m", "", msg["message"]["rendered"] or ""))
        elif msg.get("reason") == "compiler-artifact" and msg.get("executable"):
            exes[msg["target"]["name"]] = msg["executable"]
    return proc.returncode, errors, exes, proc.stderr


def check(root, target_dir, keep=False, quiet=False):
    """Builds and runs every block; returns [(where, what failed, detail)] and the counts."""
    blocks = extract(root)
    names = [b.name for b in blocks]
    assert len(set(names)) == len(names), "two blocks with one name"
    failures = []
    for b in blocks:
        if b.mode == "ignore":
            first = next((l.strip() for l in b.code if l.strip()), "")
            if not first.startswith(IGNORE_REASON):
                failures.append((b.where, "ignored without a reason",
                                 f"an `ignore` block must open with `{IGNORE_REASON} <why>`"))
    built = [b for b in blocks if b.mode in ("run", "no_run", "should_panic")]
    must_fail = [b for b in blocks if b.mode == "compile_fail"]

    project = tempfile.mkdtemp(prefix="aemstep-downstream-")
    try:
        os.makedirs(os.path.join(project, "blocks"))
        toml = ['[package]', 'name = "aemstep-downstream-check"', 'version = "0.0.0"',
                'edition = "2024"', 'publish = false', 'autobins = false', 'autoexamples = false',
                'autotests = false', 'autobenches = false', '',
                '# A workspace of its own: never a member of the repository\'s.', '[workspace]', '',
                '[dependencies]',
                f'aemstep = {{ path = {json.dumps(root)}, features = ["std"] }}', '',
                '[profile.dev]', 'debug = false', '']
        for b in built + must_fail:
            with open(os.path.join(project, "blocks", b.name + ".rs"), "w", encoding="utf-8") as f:
                f.write(doctest_source(b))
            kind = "example" if b.mode == "compile_fail" else "bin"
            toml += [f"[[{kind}]]", f'name = "{b.name}"', f'path = "blocks/{b.name}.rs"', "test = false",
                     "bench = false", *(["doc = false"] if kind == "bin" else []), ""]
        with open(os.path.join(project, "Cargo.toml"), "w") as f:
            f.write("\n".join(toml))
        lock = os.path.join(root, "Cargo.lock")
        if os.path.exists(lock):  # the versions the repository is tested with
            shutil.copy(lock, os.path.join(project, "Cargo.lock"))

        if not quiet:
            print(f"downstream: {len(built)} blocks to build and run, {len(must_fail)} compile_fail, "
                  f"project {project}, target dir {target_dir}", flush=True)
        rc, errors, exes, stderr = cargo_json(["build", "--bins", "--keep-going"], project, target_dir)
        if rc != 0 and not errors:
            raise SystemExit(f"downstream: cargo build failed outside the blocks:\n{stderr}")
        for b in built:
            if b.name in errors or b.name not in exes:
                failures.append((b.where, "does not compile", "\n".join(errors.get(b.name, ["(no artifact)"]))))
                continue
            if b.mode == "no_run":
                continue
            try:
                p = subprocess.run([exes[b.name]], cwd=project, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True, timeout=RUN_TIMEOUT)
                status, out = p.returncode, p.stdout
            except subprocess.TimeoutExpired:
                status, out = None, f"timed out after {RUN_TIMEOUT} s"
            if b.mode == "should_panic" and status != 101:
                failures.append((b.where, "should_panic but did not panic", f"exit status {status}\n{out}"))
            elif b.mode == "run" and status != 0:
                failures.append((b.where, "fails when run", f"exit status {status}\n{out[-3000:]}"))
        for b in must_fail:
            rc, errors, _, stderr = cargo_json(["build", "--example", b.name], project, target_dir)
            if rc == 0:
                failures.append((b.where, "compile_fail but compiles", ""))
            elif b.name not in errors:
                failures.append((b.where, "compile_fail: the build failed elsewhere", stderr[-3000:]))
    finally:
        if keep:
            print(f"downstream: project kept at {project}")
        else:
            shutil.rmtree(project, ignore_errors=True)
    counts = {m: sum(b.mode == m for b in blocks) for m in ("run", "no_run", "should_panic", "compile_fail", "ignore")}
    return failures, blocks, counts


def report(failures):
    for where, what, detail in failures:
        print(f"\n--- {where}: {what}")
        if detail:
            print(detail.rstrip())
    print("\ndownstream: FAILED blocks (file:line of the opening fence):")
    for where, what, _ in failures:
        print(f"  {where}: {what}")


def copy_repo(root, dest):
    """The repository's files (as in the work tree) without build output or git metadata."""
    def skip(d, names):
        return [n for n in names if n in (".git", "target") or (d == root and n == "fuzz")]
    shutil.copytree(root, dest, ignore=skip, symlinks=True)


# Blocks of every kind, appended to the self-test's copy as docs/zz_self_test.md:
# (attributes, code, what the check must report: None = passes, or the failure).
KINDS = [
    ("rust,compile_fail", ['let x: u32 = "not a number";'], None),
    ("compile_fail", ["let x: u32 = 1;"], "compile_fail but compiles"),
    ("should_panic", ['panic!("as it must");'], None),
    ("rust,should_panic", ["let x = 1;"], "should_panic but did not panic"),
    ("no_run", ["loop {}"], None),  # would time out if it were run
    ("ignore", ["not Rust"], "ignored without a reason"),
    ("rust,ignore", [IGNORE_REASON + " a self-test block.", "not Rust"], None),
    ("text", ["not Rust, not a block"], None),
    ("python", ["print('not a block')"], None),
    ("", ["# fn hidden() -> u32 { 2 }", "assert_eq!(hidden(), 2);"], None),  # rustdoc's hidden lines
    ("rust", ["fn main() {", "    std::process::exit(3);", "}"], "fails when run"),
]


def self_test(target_dir):
    """A copy of the repository with broken blocks must fail, naming exactly those."""
    tmp = tempfile.mkdtemp(prefix="aemstep-downstream-selftest-")
    try:
        copy = os.path.join(tmp, "aemstep")
        copy_repo(ROOT, copy)
        blocks = extract(copy)
        # 1. The error a user hit: a README block that names `nalgebra` directly.
        readme = next(b for b in blocks if b.path == "README.md" and b.mode == "run")
        # 2. A rustdoc block that compiles but fails when run.
        doc = next(b for b in blocks if b.path.startswith("src") and b.mode == "run"
                   and not any(re.search(r"\bfn\s+main\s*\(", l) for l in b.code))
        for b, new in ((readme, "use nalgebra::Matrix3;"), (doc, 'assert!(false, "broken by the self-test");')):
            path = os.path.join(copy, b.path)
            with open(path, encoding="utf-8") as f:
                lines = f.read().split("\n")
            # The fence's own prefix: indentation, and in rustdoc `///` or `//!` (an outer
            # doc line inside inner docs would break the crate, not the block).
            indent = re.match(r"\s*(//[/!] ?)?", lines[b.line - 1]).group(0)
            lines.insert(b.line, indent + new)  # right after the opening fence
            with open(path, "w", encoding="utf-8") as f:
                f.write("\n".join(lines))
        # 3. One block of every kind, each attribute handled as rustdoc does.
        want = [(readme.where, "does not compile"), (doc.where, "fails when run")]
        page, rel = ["# Self-test blocks", ""], os.path.join("docs", "zz_self_test.md")
        rust_kinds = 0
        for info, code, outcome in KINDS:
            where = f"{rel}:{len(page) + 1}"
            page += ["```" + info, *code, "```", ""]
            if outcome:
                want.append((where, outcome))
            rust_kinds += rust_attrs(info) is not None
        with open(os.path.join(copy, rel), "w", encoding="utf-8") as f:
            f.write("\n".join(page))
        failures, checked, _ = check(copy, target_dir, quiet=True)
        got = sorted((w, what) for w, what, _ in failures)
        detail = "\n".join(d for w, _, d in failures if w == readme.where)
        if got != sorted(want) or "nalgebra" not in detail or len(checked) != len(blocks) + rust_kinds:
            report(failures)
            raise SystemExit(f"downstream self-test FAILED: expected exactly {sorted(want)}, got {got} "
                             f"({len(checked)} blocks, expected {len(blocks) + rust_kinds})")
        print(f"downstream self-test: {len(checked)} blocks; the broken ones fail as they must, and only "
              f"they: {readme.where} (`use nalgebra::Matrix3;`: {detail.splitlines()[0] if detail else ''}), "
              f"{doc.where} (a failing assert when run), and {len(want) - 2} of the {len(KINDS)} blocks of "
              f"every kind (compile_fail, should_panic, no_run, ignore, hidden lines, fn main)")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def main():
    args = sys.argv[1:]
    target_dir = default_target_dir(ROOT)
    if "--target-dir" in args:
        target_dir = os.path.abspath(args[args.index("--target-dir") + 1])
    if "--self-test" in args:
        self_test(target_dir)
        return
    failures, blocks, counts = check(ROOT, target_dir, keep="--keep" in args)
    summary = ", ".join(f"{n} {m}" for m, n in counts.items() if n)
    if failures:
        report(failures)
        raise SystemExit(f"downstream: {len(failures)} of {len(blocks)} blocks failed ({summary})")
    print(f"downstream: all {len(blocks)} Rust code blocks checked in a crate that depends on aemstep "
          f"alone ({summary}; the ignored ones state why)")


if __name__ == "__main__":
    main()
