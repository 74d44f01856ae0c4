#!/usr/bin/env python3
"""Writes docs/layout.md (to stdout): the page a newcomer opens, its tables generated from
the module tree (the hand-written part above the page's marker line is kept as it is).

Reads src/ as text (nothing is built or run): the modules (`src/a.rs`, `src/a/mod.rs`,
`src/a/b.rs`), their line counts, which files hold a `fn step`/`fn try_step`, and every path
a file names into the crate (`use crate::…`, `use super::…`, `crate::…`/`super::…` in code,
the root re-exports of src/lib.rs followed to their module; `$crate::…` in a macro body
is the expansion site's, not counted). A *family* is a top-level
module; a family *stands on* the modules of other families its files name. Test modules
(`#[cfg(test)] mod … { … }`) and comments are left out. An *import circle* is a loop of
files naming each other, a module naming its own submodules (declarations, re-exports)
not counted and a name taken from the crate root counting as naming src/lib.rs (as
`farm-studio look` counts them); loops that close only once root names are followed to
their module are listed apart. `python3 scripts/check_docs.py` regenerates the page and compares it with the
committed one, so the page stays true as the code moves.

Usage: `python3 scripts/layout.py > docs/layout.md` (or `python3 scripts/check_docs.py --write`).
"""

import os
import re
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
SRC = os.path.join(ROOT, "src")


def modules():
    """Module path (tuple of names; the root is ()) -> file path relative to src/."""
    out = {}
    for d, _, files in os.walk(SRC):
        for f in files:
            if not f.endswith(".rs"):
                continue
            rel = os.path.relpath(os.path.join(d, f), SRC).replace(os.sep, "/")
            parts = rel[:-3].split("/")
            if parts == ["lib"]:
                parts = []
            elif parts[-1] == "mod":
                parts = parts[:-1]
            out[tuple(parts)] = rel
    return out


def strip(text):
    """The code of a file without comments, string contents and test modules."""
    text = re.sub(r'"(?:\\.|[^"\\])*"', '""', text)
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    while True:
        m = re.search(r"#\[cfg\(test\)\]\s*(?:#\[[^\]]*\]\s*)*mod\s+\w+\s*\{", text)
        if not m:
            return text
        depth, i = 0, m.end() - 1
        while i < len(text):
            depth += {"{": 1, "}": -1}.get(text[i], 0)
            if depth == 0:
                break
            i += 1
        text = text[: m.start()] + text[i + 1 :]


def use_paths(tree):
    """The paths of a use tree (`a::{b, c::{d, self}}` -> a::b, a::c::d, a::c)."""
    tree = re.sub(r"\s+", "", re.sub(r"\s+as\s+\w+", "", tree))
    m = re.match(r"^(.*?)\{(.*)\}$", tree)
    if not m:
        return [tree[:-6] if tree.endswith("::self") else tree]
    prefix, inner = m.group(1), m.group(2)
    parts, depth, cur = [], 0, ""
    for c in inner:
        if c == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        depth += (c == "{") - (c == "}")
        cur += c
    parts.append(cur)
    out = []
    for p in parts:
        if not p:
            continue
        for q in use_paths(p):
            out.append(prefix[:-2] if q == "self" else prefix + q)
    return out


def reexports(mods, root_code):
    """Root re-exports: name -> the module the name comes from."""
    out = {}
    for m in re.finditer(r"\bpub\s+use\s+([^;]+);", root_code):
        for p in use_paths(m.group(1)):
            segs = [s for s in p.split("::") if s]
            if segs and segs[0] == "crate":
                segs = segs[1:]
            target = resolve(mods, (), segs, {})
            if target and segs:
                out[segs[-1]] = target
    return out


def resolve(mods, here, segs, roots):
    """The module a path names from module `here` (None: outside the crate)."""
    if not segs:
        return None
    if segs[0] == "crate":
        base, segs = (), segs[1:]
    elif segs[0] in ("super", "self"):
        base = here
        while segs and segs[0] in ("super", "self"):
            base = base[:-1] if segs[0] == "super" else base
            segs = segs[1:]
    elif here + (segs[0],) in mods:
        base = here
    else:
        return None
    best = base
    for i in range(len(segs)):
        if base + tuple(segs[: i + 1]) in mods:
            best = base + tuple(segs[: i + 1])
        else:
            break
    if best == () and segs and segs[len(best) - len(base)] in roots:
        return roots[segs[len(best) - len(base)]]
    return best


def imports(mods, here, code, roots):
    """The modules the file of `here` names."""
    paths = []
    for m in re.finditer(r"\buse\s+([^;]+);", code):
        paths += use_paths(m.group(1))
    # (`$crate::…` in a macro body is a path of the code the macro expands into: not counted)
    paths += re.findall(r"(?<![\w$])(?:crate|super)(?:::[A-Za-z_]\w*)+", code)
    out = set()
    for p in paths:
        t = resolve(mods, here, [s for s in p.split("::") if s], roots)
        if t and t != here:
            out.add(t)
    return out


def name(mod):
    return "::".join(mod) if mod else "lib"


def circles(edges):
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out, n = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = n[0]
        n[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return sorted(out)


MARK = "<!-- Generated below by python3 scripts/layout.py: edit the page above this line. -->"


def hand_written():
    """The hand-written top of docs/layout.md, down to and with MARK (the page so far and
    MARK where it has none)."""
    path = os.path.join(ROOT, "docs", "layout.md")
    text = open(path, encoding="utf-8").read() if os.path.exists(path) else "# Layout of the crate\n"
    top = text.split(MARK)[0].rstrip("\n").split("\n") if MARK in text else text.rstrip("\n").split("\n")
    return top + ["", MARK, ""]


def page():
    mods = modules()
    code = {m: strip(open(os.path.join(SRC, f), encoding="utf-8").read()) for m, f in mods.items()}
    lines = {m: sum(1 for _ in open(os.path.join(SRC, f), encoding="utf-8")) for m, f in mods.items()}
    roots = reexports(mods, code[()])
    edges = {m: {t for t in imports(mods, m, code[m], roots) if t[: len(m)] != m} for m in mods}
    families = sorted({m[0] for m in mods if m})
    out = hand_written() + [
        "## The families and the cores they stand on",
        "",
        "Generated by `python3 scripts/layout.py` from the module tree of `src/` (the files, their",
        "lines, and the paths each file names into the crate: `use crate::…`, `use super::…`,",
        "`crate::…` in code, root re-exports followed to their module; tests and comments left",
        "out); `python3 scripts/check_docs.py --write` writes it, and the docs check regenerates",
        "it and compares it, so it stays true as the code moves. A *family* is a top-level module",
        "of `src/`; it *stands on* the modules of the other families its files name.",
        "",
        "### Families",
        "",
        "| family | files (lines) | `fn step` in | stands on |",
        "| --- | --- | --- | --- |",
    ]
    for fam in families:
        members = sorted((m for m in mods if m and m[0] == fam), key=lambda m: (len(m), m))
        files = ", ".join(f"`{mods[m].split('/')[-1]}` {lines[m]}" for m in members)
        steps = [mods[m].split("/")[-1] for m in members if re.search(r"\bfn\s+(?:try_)?step\b", code[m])]
        on = sorted({name(t) for m in members for t in edges[m] if not t or t[0] != fam})
        out.append(
            f"| `{fam}` | {files} | {', '.join(f'`{s}`' for s in steps) or '—'} | "
            f"{', '.join(f'`{o}`' for o in on) or '—'} |"
        )
    out += [
        "",
        "### The cores: who stands on each",
        "",
        "Every module another family names, with the families that name it (most used first).",
        "",
        "| module | stood on by |",
        "| --- | --- |",
    ]
    users = {}
    for m, ts in edges.items():
        for t in ts:
            if m and t and t[0] != m[0]:
                users.setdefault(t, set()).add(m[0])
    for t in sorted(users, key=lambda t: (-len(users[t]), t)):
        out.append(f"| `{name(t)}` | {', '.join(f'`{u}`' for u in sorted(users[t]))} |")
    direct = {m: {t for t in imports(mods, m, code[m], {}) if t[: len(m)] != m} for m in mods}
    out += ["", "### Import circles", ""]
    found = circles(direct)
    if found:
        out.append("Files that name each other in a loop (each should be broken):")
        out.append("")
        out += [f"- {' ↔ '.join(f'`{mods[m]}`' for m in c)}" for c in found]
    else:
        out.append("None: no files name each other in a loop (a name taken from the crate root")
        out.append("counts as naming `lib.rs`, as `farm-studio look` counts it).")
    loops = [c for c in circles(edges) if c not in found]
    if loops:
        out += [
            "",
            "Loops only through the root re-exports (`crate::Name` followed to the module that",
            "defines it; types that name each other, not an import circle):",
            "",
        ]
        out += [f"- {' ↔ '.join(f'`{mods[m]}`' for m in c)}" for c in loops]
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    sys.stdout.write(page())
