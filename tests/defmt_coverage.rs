//! Every public type of `src/` implements `defmt::Format` under feature `defmt` (issue 20),
//! or is on the commented skip list below. A text check of the sources (host, no feature
//! needed): a `pub struct`/`pub enum` counts as covered when its attributes derive
//! `defmt::Format` or some file of `src/` has `Format for Name`. That the impls compile for
//! the firmware target is `cargo check --lib --target thumbv7em-none-eabihf --features
//! defmt`.

use std::path::{Path, PathBuf};

/// Public types without `Format`, each with its reason.
const SKIP: &[(&str, &str)] = &[
    // `#[cfg(doctest)]` markers that carry the README's and docs pages' code blocks as
    // rustdoc tests: they hold no data and do not exist in a build.
    ("ReadmeDoctests", "cfg(doctest) marker"),
    ("ModalDocDoctests", "cfg(doctest) marker"),
    ("NonlinearDocDoctests", "cfg(doctest) marker"),
    ("SchemesDocDoctests", "cfg(doctest) marker"),
    ("HysteresisDocDoctests", "cfg(doctest) marker"),
    ("SpectrumDocDoctests", "cfg(doctest) marker"),
    ("ObserverDocDoctests", "cfg(doctest) marker"),
    ("EstimationDocDoctests", "cfg(doctest) marker"),
    ("DetectionDocDoctests", "cfg(doctest) marker"),
    ("HybridDocDoctests", "cfg(doctest) marker"),
    ("ControlDocDoctests", "cfg(doctest) marker"),
    ("ControlTradeoffDocDoctests", "cfg(doctest) marker"),
    ("IdaDocDoctests", "cfg(doctest) marker"),
    // Feature `std` only (host: heap-held records and IDA results); `defmt` is for firmware.
    ("Record", "std only"),
    ("DynStateSpace", "std only"),
    ("DynMeasurement", "std only"),
    ("DynSteadyState", "std only"),
    ("DynObserver", "std only"),
    ("DynEstimate", "std only"),
    ("DynKalman", "std only"),
    ("DynKalmanState", "std only"),
    ("OnFailure", "std only"),
    ("Collapse", "std only"),
    ("Plan", "std only"),
    ("Batching", "std only"),
    ("HuntFill", "std only"),
    ("Point", "std only"),
    ("Fractiles", "std only"),
    ("Curve", "std only"),
    ("DynLinear", "std only"),
    ("DynState", "std only"),
    ("DynShearBuilding", "std only"),
    ("DynNonlinear", "std only"),
    ("DynBuildingState", "std only"),
    ("DynEnergyAccount", "std only"),
];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).expect("readable src/") {
        let p = e.expect("entry").path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The public types declared in `files` (`(file, text)`) that have no `Format` impl and
/// are not in `skip`, as `file: Name`.
fn uncovered(files: &[(String, String)], skip: &[&str]) -> Vec<String> {
    // All sources with whitespace runs made one space (rustfmt may break `Format\n for`).
    let all: String = files
        .iter()
        .map(|(_, t)| t.split_whitespace().collect::<Vec<_>>().join(" ") + " ")
        .collect();
    let mut missing = Vec::new();
    for (file, text) in files {
        let lines: Vec<&str> = text.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            let t = line.trim_start();
            let Some(rest) = t
                .strip_prefix("pub struct ")
                .or_else(|| t.strip_prefix("pub enum "))
            else {
                continue;
            };
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            // The attributes (and doc comments) right above the item.
            let derived = lines[..i]
                .iter()
                .rev()
                .take_while(|l| {
                    let l = l.trim_start();
                    l.starts_with("#[") || l.starts_with("///") || l.starts_with("//")
                })
                .any(|l| l.contains("derive(defmt::Format)"));
            let by_hand = [" ", "<", " {"]
                .iter()
                .any(|end| all.contains(&format!("Format for {name}{end}")));
            if !(derived || by_hand || skip.contains(&name.as_str())) {
                missing.push(format!("{file}: {name}"));
            }
        }
    }
    missing
}

#[test]
fn every_public_type_has_defmt_format_or_a_reason() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut paths = Vec::new();
    rust_files(&src, &mut paths);
    paths.sort();
    let files: Vec<(String, String)> = paths
        .iter()
        .map(|p| {
            (
                p.strip_prefix(&src).unwrap().display().to_string(),
                std::fs::read_to_string(p).expect("readable source"),
            )
        })
        .collect();
    let declared = files
        .iter()
        .flat_map(|(_, t)| t.lines())
        .filter(|l| {
            let l = l.trim_start();
            l.starts_with("pub struct ") || l.starts_with("pub enum ")
        })
        .count();
    let skip: Vec<&str> = SKIP.iter().map(|(n, _)| *n).collect();
    let missing = uncovered(&files, &skip);
    println!(
        "{declared} public types in src/, {} skipped, {} without defmt::Format",
        skip.len(),
        missing.len()
    );
    assert!(
        declared >= 50,
        "the scan found only {declared} public types"
    );
    assert!(
        missing.is_empty(),
        "public types without defmt::Format (derive it, add it to src/defmt_impls.rs, or \
         skip it here with a reason):\n{}",
        missing.join("\n")
    );
    // Every skipped name still exists (a stale skip list hides nothing).
    for (name, _) in SKIP {
        assert!(
            files
                .iter()
                .any(|(_, t)| t.contains(&format!("pub struct {name}"))
                    || t.contains(&format!("pub enum {name}"))),
            "{name} is skipped but no longer declared"
        );
    }
}

/// The check fails on a type without an impl, and passes on the three covered forms.
#[test]
fn the_check_finds_a_type_without_format() {
    let src = |t: &str| vec![("x.rs".to_string(), t.to_string())];
    let bare = "#[derive(Clone, Copy)]\npub struct Bare<T> {\n    x: T,\n}\n";
    assert_eq!(uncovered(&src(bare), &[]), vec!["x.rs: Bare".to_string()]);
    assert!(uncovered(&src(bare), &["Bare"]).is_empty());
    let derived = "/// Doc.\n#[cfg_attr(feature = \"defmt\", derive(defmt::Format))]\n#[derive(Clone)]\npub enum E {\n    A,\n}\n";
    assert!(uncovered(&src(derived), &[]).is_empty());
    let manual = format!("{bare}impl<T: defmt::Format> defmt::Format for Bare<T> {{}}\n");
    assert!(uncovered(&src(&manual), &[]).is_empty());
    // A derive two items up does not cover the next one.
    let two = format!("{derived}\n{bare}");
    assert_eq!(uncovered(&src(&two), &[]), vec!["x.rs: Bare".to_string()]);
}
