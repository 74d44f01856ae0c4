//! The fuzz corpus as regression tests (issue 10), on the stable toolchain: every kept
//! input of `fuzz/corpus/<target>/` (the minimized corpus of `scripts/fuzz.sh`) and of
//! `fuzz/regressions/<target>/` (each input a fuzz run found a property broken by, named
//! after the fix) is replayed through the same checks the fuzz targets run
//! (`fuzz/src/checks/`, included here), and the test fails if any property breaks.
//!
//! `AEMSTEP_FUZZ_REPLAY=path/to/input` replays one file (its target from its directory's
//! name), e.g. a crash artifact of a fuzz run, with the broken property printed.

#[path = "../fuzz/src/checks/mod.rs"]
mod checks;

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz")
}

/// The kept inputs of `dir/<target>/`, sorted, as `(target, path)`.
fn inputs(dir: &str) -> Vec<(&'static str, PathBuf)> {
    let mut out = Vec::new();
    for t in checks::TARGETS {
        let d = root().join(dir).join(t);
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        let mut files: Vec<PathBuf> = rd
            .map(|e| e.expect("readable directory entry").path())
            .filter(|p| p.is_file())
            .collect();
        files.sort();
        out.extend(files.into_iter().map(|p| (t, p)));
    }
    out
}

/// Replay `files`; the failures as `(path, message)`.
fn replay(files: &[(&'static str, PathBuf)]) -> Vec<(String, String)> {
    // (A failing input's panic is also printed by the default hook, into this test's
    // captured output; the hook is process-global, so it is not swapped here.)
    let mut failed = Vec::new();
    for (t, p) in files {
        let data = std::fs::read(p).expect("readable input");
        if let Err(e) = std::panic::catch_unwind(|| checks::run(t, &data)) {
            let msg = e
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            failed.push((p.display().to_string(), msg));
        }
    }
    failed
}

fn assert_replays(dir: &str, min_files: usize) {
    let files = inputs(dir);
    assert!(
        files.len() >= min_files,
        "fuzz/{dir}: {} inputs, expected at least {min_files}",
        files.len()
    );
    let failed = replay(&files);
    for t in checks::TARGETS {
        let n = files.iter().filter(|(x, _)| *x == t).count();
        println!("{dir}/{t}: {n} inputs replayed");
    }
    assert!(
        failed.is_empty(),
        "{} of {} inputs of fuzz/{dir} break a property:\n{}",
        failed.len(),
        files.len(),
        failed
            .iter()
            .map(|(p, m)| format!("{p}: {m}"))
            .collect::<Vec<_>>()
            .join("\n")
    );
}

/// Every input of the minimized corpus keeps every property (each target has a corpus).
#[test]
fn corpus_keeps_every_property() {
    if let Ok(one) = std::env::var("AEMSTEP_FUZZ_REPLAY") {
        let p = PathBuf::from(one);
        let t = checks::TARGETS
            .into_iter()
            .find(|t| p.components().any(|c| c.as_os_str().to_str() == Some(t)))
            .expect("the input's path names its target");
        checks::run(t, &std::fs::read(&p).expect("readable input"));
        println!(
            "{}: every property holds\n  data: {}",
            p.display(),
            checks::context()
        );
        return;
    }
    for t in checks::TARGETS {
        assert!(
            inputs("corpus").iter().any(|(x, _)| *x == t),
            "fuzz/corpus/{t} is empty"
        );
    }
    assert_replays("corpus", checks::TARGETS.len());
}

/// Every input a fuzz run found a property broken by (kept in `fuzz/regressions/`) keeps
/// every property since its fix.
#[test]
fn regressions_stay_fixed() {
    assert_replays("regressions", 1);
}
