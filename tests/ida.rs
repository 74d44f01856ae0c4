//! Incremental dynamic analysis (`aemstep::ida`): hunt-and-fill on an analysis with a
//! known IDA curve (the sequence of intensities worked by hand, the collapse bracketed to
//! the resolution, the budget kept, the gaps filled, a record that never collapses, one
//! that collapses at the first intensity, collapse by EDP or by a failed analysis, abort),
//! stripes, bad settings as typed errors, serial == parallel bit for bit, the progress
//! callback, fractiles against a hand computation, `Sa(T₁)`; and one real run: the
//! yielding 5-storey building (`scenes/ida/building.rs`) under El Centro, whose elastic
//! points equal the linear analysis scaled.
#![cfg(feature = "std")]

#[path = "../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../scenes/ida/building.rs"]
mod ida_scene;

use std::sync::Mutex;

use aemstep::ida::{self, Collapse, Curve, HuntFill, OnFailure, Point};
use aemstep::nalgebra::SVector;
use aemstep::{Error, Linear, Param, Stepper, models};

/// A record of the toy analysis: its collapse intensity `c`.
#[derive(Clone, Copy, Debug)]
struct Toy {
    c: f64,
}

/// The toy IDA curve: `EDP = a·im / (1 − im/c)` (linear with slope `a = 0.01` at small
/// intensities, softening, unbounded at `c`); from `im ≥ c` the analysis fails
/// (`NotConverged`), as a Newton solve of a structure that lost its stiffness would.
fn toy(r: &Toy, im: f64) -> Result<f64, Error> {
    if im >= r.c {
        Err(Error::NotConverged)
    } else {
        Ok(0.01 * im / (1.0 - im / r.c))
    }
}

/// Dyadic settings (every intensity exact in binary): hunt 0.125, 0.375, 0.75, 1.25,
/// 1.875, 2.625, …; resolution 0.05, 12 runs, collapse by failure only.
const DYADIC: HuntFill = HuntFill {
    first: 0.125,
    step: 0.25,
    step_increment: 0.125,
    resolution: 0.05,
    runs: 12,
    collapse: Collapse {
        edp: f64::INFINITY,
        on_failure: OnFailure::Collapse,
    },
};

fn intensities(c: &Curve) -> Vec<f64> {
    c.points.iter().map(|p| p.intensity).collect()
}

fn sorted(c: &Curve) -> bool {
    c.points.windows(2).all(|w| w[0].intensity < w[1].intensity)
}

/// The largest gap between the non-collapsing intensities below the collapse (from 0).
fn largest_gap(c: &Curve) -> f64 {
    let top = c.collapse.map_or(f64::INFINITY, |b| b[1]);
    let mut xs = vec![0.0];
    xs.extend(
        c.points
            .iter()
            .filter(|p| !p.collapsed && p.intensity < top)
            .map(|p| p.intensity),
    );
    xs.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max)
}

/// The whole sequence by hand (collapse at 1.6): hunt 0.125, 0.375, 0.75, 1.25, 1.875 (C);
/// bisection 1.5625, 1.71875 (C), 1.640625 (C), 1.6015625 (C): bracket
/// [1.5625, 1.6015625], width 0.039 ≤ 0.05 after 9 runs; fill the largest gaps of
/// {0, .125, .375, .75, 1.25, 1.5625}: [0.75, 1.25] → 1.0, then [0.375, 0.75] → 0.5625,
/// then [1.25, 1.5625] → 1.40625: 12 runs.
#[test]
fn hunt_and_fill_sequence_by_hand() {
    let c = ida::trace(&Toy { c: 1.6 }, &DYADIC, toy).unwrap();
    assert_eq!(
        intensities(&c),
        [
            0.125, 0.375, 0.5625, 0.75, 1.0, 1.25, 1.40625, 1.5625, 1.6015625, 1.640625, 1.71875,
            1.875
        ]
    );
    assert_eq!(c.collapse, Some([1.5625, 1.6015625]));
    assert_eq!(c.capacity(), Some(1.5625));
    for p in &c.points {
        assert_eq!(p.collapsed, p.intensity >= 1.6);
        if p.collapsed {
            assert_eq!((p.edp, p.error), (f64::INFINITY, Some(Error::NotConverged)));
        } else {
            assert_eq!(p.edp, toy(&Toy { c: 1.6 }, p.intensity).unwrap());
            assert_eq!(p.error, None);
        }
    }
}

/// Over many collapse intensities: the bracket holds the true collapse intensity and is at
/// most the resolution wide, the budget is spent exactly (never exceeded), the points are
/// sorted, and the fill narrows the widest gap: the last 3 runs leave no gap wider than
/// the 9-run trace (the same first 9 runs) had.
#[test]
fn brackets_to_the_resolution_within_the_budget() {
    let nine = HuntFill { runs: 9, ..DYADIC };
    let mut filled = 0;
    for k in 0..200 {
        let cap = 0.13 + 0.0137 * k as f64; // 0.13 … 2.86: collapse on the 2nd to 7th hunt step
        let c = ida::trace(&Toy { c: cap }, &DYADIC, toy).unwrap();
        let [lo, hi] = c.collapse.unwrap();
        assert!(
            lo < cap && cap <= hi && hi - lo <= DYADIC.resolution,
            "c = {cap}: [{lo}, {hi}]"
        );
        assert_eq!(c.points.len(), DYADIC.runs, "c = {cap}");
        assert!(sorted(&c), "c = {cap}");
        let before = ida::trace(&Toy { c: cap }, &nine, toy).unwrap();
        assert!(
            before.points.iter().all(|p| c.points.contains(p)),
            "c = {cap}"
        );
        assert!(largest_gap(&c) <= largest_gap(&before), "c = {cap}");
        filled += (largest_gap(&c) < largest_gap(&before)) as u32;
    }
    assert!(filled > 100, "{filled}");
}

/// Collapse defined by an EDP limit: the known collapse intensity of the toy,
/// `EDP(im) = E` at `im* = E / (a + E/c)`, bracketed to the resolution.
#[test]
fn collapse_by_edp() {
    let e = 0.05;
    let s = HuntFill {
        collapse: Collapse {
            edp: e,
            on_failure: OnFailure::Collapse,
        },
        ..DYADIC
    };
    // At c = 0.9 the hunt jumps from 0.75 (EDP 0.045) to 1.25 ≥ c, a failed analysis:
    // collapse either way, and the bisection finds the EDP limit inside.
    for cap in [0.9, 1.6, 3.0] {
        let star = e / (0.01 + e / cap);
        let c = ida::trace(&Toy { c: cap }, &s, toy).unwrap();
        let [lo, hi] = c.collapse.unwrap();
        assert!(
            lo < star && star <= hi && hi - lo <= s.resolution,
            "{star} in [{lo}, {hi}]"
        );
        assert!(
            c.points
                .iter()
                .all(|p| p.collapsed == (p.edp >= e) && p.error.is_none() == (p.intensity < cap))
        );
    }
}

/// A record that never collapses spends the budget hunting up: 12 intensities of the hunt,
/// no bracket, no fill.
#[test]
fn never_collapses_budget_reached() {
    let c = ida::trace(&Toy { c: 1e9 }, &DYADIC, toy).unwrap();
    let (mut im, mut step, mut want) = (0.125, 0.25, vec![]);
    for _ in 0..12 {
        want.push(im);
        im += step;
        step += 0.125;
    }
    assert_eq!(intensities(&c), want);
    assert_eq!(*want.last().unwrap(), 0.125 + 11.0 * 0.25 + 55.0 * 0.125);
    assert_eq!((c.collapse, c.capacity()), (None, None));
    assert!(c.points.iter().all(|p| !p.collapsed));
}

/// A record that collapses at the first intensity: the bracket is [0, first] bisected, and
/// the budget fills below the collapse.
#[test]
fn collapses_at_the_first_intensity() {
    let c = ida::trace(&Toy { c: 0.05 }, &DYADIC, toy).unwrap();
    let [lo, hi] = c.collapse.unwrap();
    // 0.125 (C), 0.0625 (C), 0.03125: [0.03125, 0.0625], width 0.03125 ≤ 0.05.
    assert_eq!([lo, hi], [0.03125, 0.0625]);
    assert_eq!(c.points.len(), 12);
    assert!(sorted(&c));
    assert_eq!(c.points.iter().filter(|p| p.collapsed).count(), 2);
    // nine fill runs split [0, 0.03125] evenly: 16 gaps of 1/512 after 15 splits, here 10
    // points → the widest gap is 1/256.
    assert_eq!(largest_gap(&c), 0.03125 / 8.0);
    // The same through the suite API, one collapse at once
    let curves = ida::hunt_fill(&[Toy { c: 0.05 }], &DYADIC, 2, toy, None).unwrap();
    assert_eq!(curves, vec![c]);
}

/// A failed analysis: collapse (kept, with its error) or abort (the error returned); an
/// EDP that is NaN is a failure with `NonFiniteState`.
#[test]
fn failures_collapse_or_abort() {
    let abort = HuntFill {
        collapse: Collapse {
            edp: f64::INFINITY,
            on_failure: OnFailure::Abort,
        },
        ..DYADIC
    };
    assert_eq!(
        ida::trace(&Toy { c: 1.0 }, &abort, toy),
        Err(Error::NotConverged)
    );
    let suite = [Toy { c: 1e9 }, Toy { c: 1.0 }, Toy { c: 0.5 }];
    assert_eq!(
        ida::hunt_fill(&suite, &abort, 2, toy, None),
        Err(Error::NotConverged)
    );
    let nan = |_: &Toy, im: f64| -> Result<f64, Error> { Ok(if im > 1.0 { f64::NAN } else { im }) };
    let c = ida::trace(&Toy { c: 0.0 }, &DYADIC, nan).unwrap();
    let p = c.points.iter().find(|p| p.collapsed).unwrap();
    assert_eq!(
        (p.edp, p.error),
        (f64::INFINITY, Some(Error::NonFiniteState))
    );
    assert!(c.collapse.unwrap()[1] > 1.0 && c.collapse.unwrap()[0] <= 1.0);
    assert_eq!(
        ida::trace(&Toy { c: 0.0 }, &abort, nan),
        Err(Error::NonFiniteState)
    );
}

/// Issue 31: an EDP of `−∞` was kept as a non-collapsing point (garbage on the curve and
/// in the fractiles); now it is a failed analysis, as NaN is. `+∞` stays a collapse by the
/// EDP rule, with no error.
#[test]
fn negative_infinite_edp_is_a_failed_analysis() {
    let neg = |_: &Toy, im: f64| -> Result<f64, Error> {
        Ok(if im > 1.0 { f64::NEG_INFINITY } else { im })
    };
    let c = ida::trace(&Toy { c: 0.0 }, &DYADIC, neg).unwrap();
    assert!(c.points.iter().all(|p| p.edp > f64::NEG_INFINITY));
    let p = c.points.iter().find(|p| p.collapsed).unwrap();
    assert_eq!(
        (p.edp, p.error),
        (f64::INFINITY, Some(Error::NonFiniteState))
    );
    let abort = HuntFill {
        collapse: Collapse {
            edp: f64::INFINITY,
            on_failure: OnFailure::Abort,
        },
        ..DYADIC
    };
    assert_eq!(
        ida::trace(&Toy { c: 0.0 }, &abort, neg),
        Err(Error::NonFiniteState)
    );
    let pos =
        |_: &Toy, im: f64| -> Result<f64, Error> { Ok(if im > 1.0 { f64::INFINITY } else { im }) };
    let c = ida::trace(&Toy { c: 0.0 }, &abort, pos).unwrap();
    let p = c.points.iter().find(|p| p.collapsed).unwrap();
    assert_eq!((p.edp, p.error), (f64::INFINITY, None));
}

#[test]
fn bad_settings_are_typed_errors() {
    let bad = |s: HuntFill| {
        // The collapse limit is named as such; every other setting as hunt-and-fill's.
        let which = if s.collapse.edp > 0.0 {
            Param::HuntFill
        } else {
            Param::CollapseLimit
        };
        assert_eq!(
            ida::trace(&Toy { c: 1.0 }, &s, toy),
            Err(Error::InvalidParameter(which)),
            "{s:?}"
        );
        assert_eq!(
            ida::hunt_fill(&[Toy { c: 1.0 }], &s, 2, toy, None),
            Err(Error::InvalidParameter(which))
        );
    };
    for x in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        bad(HuntFill { first: x, ..DYADIC });
        bad(HuntFill { step: x, ..DYADIC });
        bad(HuntFill {
            resolution: x,
            ..DYADIC
        });
        bad(HuntFill {
            collapse: Collapse {
                edp: if x == f64::INFINITY { -x } else { x },
                on_failure: OnFailure::Collapse,
            },
            ..DYADIC
        });
    }
    for x in [-0.1, f64::NAN, f64::INFINITY] {
        bad(HuntFill {
            step_increment: x,
            ..DYADIC
        });
    }
    bad(HuntFill { runs: 0, ..DYADIC });
    bad(HuntFill {
        runs: 10_001,
        ..DYADIC
    });
    bad(HuntFill {
        step: 1e308,
        ..DYADIC
    }); // the hunt could reach 0.125 + 12e308: overflow
    let never = |_: &Toy, _: f64| -> Result<f64, Error> { panic!("no run before the checks") };
    let rule = DYADIC.collapse;
    for ims in [&[1.0, 0.0][..], &[f64::NAN], &[-1.0], &[f64::INFINITY]] {
        assert_eq!(
            ida::stripes(&[Toy { c: 1.0 }], ims, &rule, 2, never, None),
            Err(Error::InvalidParameter(Param::Intensity))
        );
    }
    let zero_edp = Collapse { edp: 0.0, ..rule };
    assert_eq!(
        ida::stripes(&[Toy { c: 1.0 }], &[1.0], &zero_edp, 2, never, None),
        Err(Error::InvalidParameter(Param::CollapseLimit))
    );
    let c = ida::trace(&Toy { c: 1.0 }, &DYADIC, toy).unwrap();
    assert_eq!(
        ida::fractiles(&[], &[0.01], &[0.5]),
        Err(Error::InvalidParameter(Param::Fractiles))
    );
    for e in [-0.01, f64::NAN, f64::INFINITY] {
        assert_eq!(
            ida::fractiles(std::slice::from_ref(&c), &[e], &[0.5]),
            Err(Error::InvalidParameter(Param::Fractiles))
        );
    }
    for q in [-0.1, 1.1, f64::NAN] {
        assert_eq!(
            ida::fractiles(std::slice::from_ref(&c), &[0.01], &[q]),
            Err(Error::InvalidParameter(Param::Fractiles))
        );
    }
    assert!(HuntFill::default() == HuntFill::DEFAULT);
}

/// An analysis whose bits depend on every operation (an explicit oscillator loop), so a
/// different order of work or sharing between threads would show.
fn chaotic(r: &Toy, im: f64) -> Result<f64, Error> {
    let (mut u, mut v) = (0.0f64, 0.0f64);
    for n in 0..3000 {
        let a = -4.0 * u - 0.05 * v - r.c * u * u * u + im * (n as f64 * 0.013).sin();
        v += 0.002 * a;
        u += 0.002 * v;
    }
    let edp = u.abs() + v.abs() * 1e-3;
    if im > r.c * 3.0 {
        Err(Error::NotConverged)
    } else {
        Ok(edp)
    }
}

fn bits(curves: &[Curve]) -> Vec<(u64, u64, bool)> {
    curves
        .iter()
        .flat_map(|c| c.points.iter())
        .map(|p| (p.intensity.to_bits(), p.edp.to_bits(), p.collapsed))
        .collect()
}

#[test]
fn serial_equals_parallel_bit_for_bit() {
    let suite: Vec<Toy> = (0..9)
        .map(|i| Toy {
            c: 0.3 + 0.21 * i as f64,
        })
        .collect();
    let s = HuntFill {
        collapse: Collapse {
            edp: 0.4,
            on_failure: OnFailure::Collapse,
        },
        ..DYADIC
    };
    let alone: Vec<Curve> = suite
        .iter()
        .map(|r| ida::trace(r, &s, chaotic).unwrap())
        .collect();
    assert!(alone.iter().any(|c| c.collapse.is_some()));
    for threads in [1, 2, 3, 0, 20] {
        let got = ida::hunt_fill(&suite, &s, threads, chaotic, None).unwrap();
        assert_eq!(bits(&got), bits(&alone), "threads = {threads}");
        assert_eq!(got, alone);
    }
    let ims: Vec<f64> = (1..=20).map(|k| k as f64 * 0.1).collect();
    let one = ida::stripes(&suite, &ims, &s.collapse, 1, chaotic, None).unwrap();
    for threads in [2, 0] {
        let got = ida::stripes(&suite, &ims, &s.collapse, threads, chaotic, None).unwrap();
        assert_eq!(bits(&got), bits(&one), "threads = {threads}");
    }
    // Each stripe point is the analysis at that intensity, classified by the rule.
    for (r, c) in suite.iter().zip(&one) {
        assert_eq!(intensities(c), ims);
        for p in &c.points {
            match chaotic(r, p.intensity) {
                Ok(e) => assert_eq!((p.edp, p.collapsed), (e, e >= 0.4)),
                Err(e) => assert_eq!((p.collapsed, p.error), (true, Some(e))),
            }
        }
        let want = c.points.iter().find(|p| p.collapsed).map(|p| p.intensity);
        assert_eq!(c.collapse.map(|b| b[1]), want);
    }
}

/// Stripes given in any order come back sorted; the bracket is the lowest collapse and
/// the highest non-collapse below it.
#[test]
fn stripes_sorted_and_bracketed() {
    let ims = [1.5, 0.5, 2.5, 1.0, 2.0];
    let curves = ida::stripes(
        &[Toy { c: 1.7 }, Toy { c: 9.0 }],
        &ims,
        &DYADIC.collapse,
        2,
        toy,
        None,
    )
    .unwrap();
    assert_eq!(intensities(&curves[0]), [0.5, 1.0, 1.5, 2.0, 2.5]);
    assert_eq!(curves[0].collapse, Some([1.5, 2.0]));
    assert_eq!(curves[1].collapse, None);
    assert!(
        ida::stripes(&[] as &[Toy], &ims, &DYADIC.collapse, 2, toy, None)
            .unwrap()
            .is_empty()
    );
}

/// The progress callback: every run reported once, `done` distinct in `1..=total`, and
/// `total` the budget of the whole suite.
#[test]
fn progress_reports_every_run() {
    let suite: Vec<Toy> = (0..5)
        .map(|i| Toy {
            c: 0.4 + 0.5 * i as f64,
        })
        .collect();
    let seen = Mutex::new(Vec::new());
    let report = |done: usize, total: usize| seen.lock().unwrap().push((done, total));
    ida::hunt_fill(&suite, &DYADIC, 2, toy, Some(&report)).unwrap();
    let mut got = seen.into_inner().unwrap();
    got.sort();
    let want: Vec<(usize, usize)> = (1..=60).map(|d| (d, 60)).collect();
    assert_eq!(got, want);
    let seen = Mutex::new(Vec::new());
    let report = |done: usize, total: usize| seen.lock().unwrap().push((done, total));
    ida::stripes(
        &suite,
        &[0.5, 1.0, 1.5],
        &DYADIC.collapse,
        3,
        toy,
        Some(&report),
    )
    .unwrap();
    let mut got = seen.into_inner().unwrap();
    got.sort();
    assert_eq!(got, (1..=15).map(|d| (d, 15)).collect::<Vec<_>>());
}

fn pt(intensity: f64, edp: f64) -> Point {
    Point {
        intensity,
        edp,
        collapsed: edp.is_infinite(),
        error: None,
    }
}

/// Fractiles of three hand-made curves, worked by hand (numpy's linear quantile,
/// `h = (n − 1) q`): A collapses after (2, 0.03); B never collapses (censored past
/// 0.05); C collapses after (1.5, 0.02).
#[test]
fn fractiles_by_hand() {
    let inf = f64::INFINITY;
    let a = Curve::from_points(vec![pt(3.0, inf), pt(1.0, 0.01), pt(2.0, 0.03)]);
    let b = Curve::from_points(vec![pt(1.0, 0.02), pt(2.0, 0.05)]);
    let c = Curve::from_points(vec![pt(0.5, 0.01), pt(1.5, 0.02), pt(2.0, inf)]);
    assert_eq!(
        (a.collapse, b.collapse, c.collapse),
        (Some([2.0, 3.0]), None, Some([1.5, 2.0]))
    );
    assert!((a.intensity_at(0.02).0 - 1.5).abs() < 1e-15 && !a.intensity_at(0.02).1);
    assert_eq!(a.intensity_at(0.04), (2.0, false)); // the flatline
    assert_eq!(b.intensity_at(0.06), (2.0, true)); // censored
    let f = ida::fractiles(
        &[a, b, c],
        &[0.0, 0.01, 0.02, 0.04, 0.06],
        &[0.16, 0.5, 0.84],
    )
    .unwrap();
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-15 * y.abs().max(1.0);
    // 0.01: A 1.0, B 0.5, C 0.5 → [0.5, 0.5, 1.0]: 0.5, 0.5, 0.5 + 0.68·0.5
    // 0.02: A 1.5, B 1.0, C 1.5 → [1, 1.5, 1.5]: 1 + 0.32·0.5, 1.5, 1.5
    // 0.04: A 2 (flat), B 1 + 2/3, C 1.5 (flat) → [1.5, 5/3, 2]: 1.5 + 0.32/6, 5/3, 5/3 + 0.68/3
    // 0.06: A 2, B ≥ 2 (censored), C 1.5 → [1.5, 2, 2 or more]: 1.66, 2, NaN (2 to ∞)
    let want = [
        [0.0, 0.5, 1.16, 1.5 + 0.32 / 6.0, 1.66],
        [0.0, 0.5, 1.5, 5.0 / 3.0, 2.0],
        [0.0, 0.84, 1.5, 5.0 / 3.0 + 0.68 / 3.0, f64::NAN],
    ];
    for (k, row) in want.iter().enumerate() {
        for (j, &w) in row.iter().enumerate() {
            let g = f.at(k, j).unwrap();
            assert!(
                close(g, w) || (g.is_nan() && w.is_nan()),
                "q {k}, level {j}: {g} vs {w}"
            );
        }
    }
    // the named axes: as given, and out of range is None, not a panic
    assert_eq!(f.quantiles(), &[0.16, 0.5, 0.84]);
    assert_eq!(f.edp(), &[0.0, 0.01, 0.02, 0.04, 0.06]);
    assert_eq!((f.at(3, 0), f.at(0, 5), f.curve(3)), (None, None, None));
    assert_eq!(f.curve(1).unwrap().len(), 5);
    assert_eq!(f.as_slice()[5..10], *f.curve(1).unwrap());
}

/// `Sa(T₁)`: linear in the record, typed errors for bad input.
#[test]
fn spectral_acceleration_scaling() {
    let ag = &elcentro::AG_F64[..];
    let sa = ida::spectral_acceleration(ag, elcentro::DT, 0.5, 0.05).unwrap();
    let doubled: Vec<f64> = ag.iter().map(|a| 2.0 * a).collect();
    let sa2 = ida::spectral_acceleration(&doubled, elcentro::DT, 0.5, 0.05).unwrap();
    assert_eq!(sa2, 2.0 * sa); // doubling is exact in binary, and so is every step
    assert!(sa > 5.0 && sa < 15.0, "{sa}"); // El Centro NS near 0.5 s: about 1 g
    assert_eq!(
        ida::spectral_acceleration(ag, 0.02, 0.0, 0.05),
        Err(Error::InvalidPeriod)
    );
    assert_eq!(
        ida::spectral_acceleration(ag, 0.02, 0.5, 1.0),
        Err(Error::InvalidDamping)
    );
    assert_eq!(
        ida::spectral_acceleration(ag, 0.0, 0.5, 0.05),
        Err(Error::InvalidTimeStep)
    );
    assert_eq!(
        ida::spectral_acceleration(&[1.0, f64::NAN], 0.02, 0.5, 0.05),
        Err(Error::NonFiniteInput)
    );
}

/// The first 20 s of El Centro (4000 steps of 5 ms), as `tests/batch.rs` runs it.
const STEPS: u64 = 4000;

/// The linear building (`five_storey_building`'s M, C, K; the same h and ground motion):
/// the peak absolute storey drift under the record ×1 (m).
fn linear_peak_drift(ag: &[f64]) -> f64 {
    let (m, c, k) = models::five_storey_building();
    let (m, c, k) = (
        models::matrix_of(&m),
        models::matrix_of(&c),
        models::matrix_of(&k),
    );
    let lin = Linear::<f64, 5>::new(&m, &c, &k, ida_scene::H).unwrap();
    let bld = ida_scene::building().unwrap();
    let zero = SVector::<f64, 5>::zeros();
    let mut s = lin
        .start(
            &zero,
            &zero,
            &bld.ground_load(ida_scene::ground(ag, 1.0, 0)),
        )
        .unwrap();
    let mut peak = 0.0f64;
    for n in 1..=STEPS {
        lin.step(&mut s, &bld.ground_load(ida_scene::ground(ag, 1.0, n)));
        peak = models::drifts(s.u())
            .iter()
            .fold(peak, |m, d| m.max(d.abs()));
    }
    peak
}

/// The yielding building under El Centro by hunt-and-fill (12 runs, collapse at 9 cm of
/// drift): below the yield drift (`FY/k` = 3 cm) no storey yields, so the run is the
/// linear analysis (`Linear`, the same AEM step, h and ground motion) scaled:
/// `drift(s) = s · drift_linear(1)`. They differ by rounding only: the same step, Newton
/// solving an elastic step exactly in its first iteration, and a linear response to a
/// scaled load equal to the scaled response up to the roundings of each step, which the
/// damping keeps from accumulating. Measured: 6 elastic points (s = 0.05 … 1.025), worst
/// relative difference 4.4e-16 (2 ulp); the tolerance 1e-14 (45 ulp) leaves room for
/// another order of operations (FMA) on another target, not for a wrong scaling (any
/// modelling difference, e.g. another h or interpolation, shows at 1e-3 and more).
#[test]
fn yielding_building_elastic_part_is_the_linear_analysis_scaled() {
    let ag = &elcentro::AG_F64[..];
    let (bld, stepper) = (
        ida_scene::building().unwrap(),
        ida_scene::stepper().unwrap(),
    );
    let analysis = |rec: &&[f64], s: f64| ida_scene::peak_drift(&bld, &stepper, rec, s, STEPS);
    let settings = HuntFill {
        first: 0.05,
        step: 0.15,
        step_increment: 0.1,
        resolution: 0.05,
        runs: 12,
        collapse: Collapse {
            edp: 0.09, // 3 % of a 3 m storey, 3 yield drifts
            on_failure: OnFailure::Collapse,
        },
    };
    let curves = ida::hunt_fill(&[ag], &settings, 2, analysis, None).unwrap();
    let c = &curves[0];
    // The pool changes nothing: the record alone on the caller's thread, bit for bit.
    let alone = ida::trace(&ag, &settings, analysis).unwrap();
    assert_eq!(bits(std::slice::from_ref(&alone)), bits(&curves));
    let d1 = linear_peak_drift(ag);
    let yield_drift = ida_scene::FY / models::FIVE_STOREY_STIFFNESS;
    let mut elastic = 0;
    let mut worst = 0.0f64;
    for p in &c.points {
        if p.edp < yield_drift {
            let rel = (p.edp - p.intensity * d1).abs() / (p.intensity * d1);
            println!(
                "  s = {}: drift {:e} m, s·linear {:e} m",
                p.intensity,
                p.edp,
                p.intensity * d1
            );
            worst = worst.max(rel);
            elastic += 1;
        }
    }
    println!(
        "linear drift ×1 {d1:.6e} m; {} points, {elastic} elastic, worst relative {worst:.2e}; collapse {:?}",
        c.points.len(),
        c.collapse
    );
    assert!(elastic >= 2, "{:?}", c.points);
    assert!(worst <= 1e-14, "{worst:e}");
    let [lo, hi] = c.collapse.expect("collapses by drift");
    assert!(hi - lo <= settings.resolution);
    assert_eq!(c.points.len(), settings.runs);
}
