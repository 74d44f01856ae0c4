//! The lane-batched stepper (`aemstep::lanes`) against `L` single analyses
//! (`Nonlinear::try_step_with_history`, the independent reference here: the lanes share
//! none of its Newton code): every lane's state, history, Newton report and failure, bit
//! for bit (`to_bits`), at L = 1, 2, 3, 4, 8, with records of different lengths and
//! failing lanes, at the dispatch level the CPU gives each width (AVX-512 for `f64` at
//! L = 8 where the CPU has it). The unit test `lanes::tests` runs every level (SSE2, AVX,
//! AVX-512) in one process; the SSE2-only control build
//! (`RUSTFLAGS='--cfg aemstep_control="sse2-only"'`) runs these too: the same bits.

#[path = "../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../scenes/ida/building.rs"]
mod scene;

use aemstep::hysteresis::{
    Bilinear, BoucWen, Friction, HistoryModel, Law, Parallel, ShearBuilding,
};
use aemstep::lanes::{Failure, LaneLaw, LaneState, LaneStepper};
use aemstep::nalgebra::SVector;
use aemstep::{Error, NewtonReport, NewtonSettings, Nonlinear, State, models};

/// Lane `l`'s record scale: from elastic (0.5) to far past yield (11).
fn scale(l: usize) -> f64 {
    0.5 + 1.5 * l as f64
}

/// Lane `l`'s record length (steps): all different, 600 … 1650.
fn length(l: usize) -> u64 {
    600 + 150 * (l as u64 % 8)
}

/// The ground acceleration of lane `l` at step `n`; lane `nan_lane` gets a NaN at step 333
/// (its analysis fails there with `NonFiniteInput`).
fn ground(l: usize, n: u64, nan_lane: usize) -> f64 {
    if l == nan_lane && n == 333 {
        return f64::NAN;
    }
    scene::ground(&elcentro::AG_F64, scale(l), n)
}

/// The bits of a state (`u`, `v`, `a`) and its step count.
type Bits = (Vec<u64>, u64);

/// The bits of a state, to compare.
fn state_bits<const N: usize>(s: &State<f64, N>) -> Bits {
    let v = s.u().iter().chain(s.v().iter()).chain(s.a().iter());
    (v.map(|x| x.to_bits()).collect(), s.steps())
}

/// The bits of a state and a history, to compare (`{:?}` of an `f64` round-trips, so
/// equal text is equal bits).
fn bits_of<const N: usize, H: core::fmt::Debug>(s: &State<f64, N>, h: &[H; N]) -> String {
    format!("{:?} {h:?}", state_bits(s))
}

/// One analysis by the single stepper, as `run` defines it: every state after a step, and
/// the outcome.
fn single<Lw: Law<f64>, const N: usize>(
    building: &ShearBuilding<f64, Lw, N>,
    stepper: &Nonlinear<f64, N>,
    steps: u64,
    ground: impl Fn(u64) -> f64,
) -> (Vec<Bits>, Result<(), Failure>) {
    let zero = SVector::<f64, N>::zeros();
    let (mut s, mut h) = match stepper.start_with_history(
        building,
        &zero,
        &zero,
        &building.ground_load(ground(0)),
        &building.initial_history(),
    ) {
        Ok(x) => x,
        Err(error) => return (vec![], Err(Failure { step: 0, error })),
    };
    let mut seen = vec![];
    for n in 1..=steps {
        let p = building.ground_load(ground(n));
        if let Err(error) = stepper.try_step_with_history(building, &mut s, &mut h, &p) {
            return (seen, Err(Failure { step: n, error }));
        }
        seen.push(state_bits(&s));
    }
    (seen, Ok(()))
}

/// `L` lanes by `LaneStepper::run` against `L` single analyses: every state after every
/// step, and each lane's outcome.
fn run_matches<Lw: LaneLaw<f64>, const N: usize, const L: usize>(
    building: &ShearBuilding<f64, Lw, N>,
    settings: NewtonSettings<f64>,
    nan_lane: usize,
) -> [Result<(), Failure>; L] {
    let lanes = LaneStepper::<f64, N, L>::new(scene::H, settings).unwrap();
    let steps: [u64; L] = core::array::from_fn(length);
    let mut seen: Vec<Vec<Bits>> = vec![vec![]; L];
    let outcome = lanes.run(
        building,
        steps,
        |l, n| ground(l, n, nan_lane),
        |state: &LaneState<f64, N, L>, stepped| {
            assert!(state.lane(L).is_none());
            for l in 0..L {
                if stepped[l] {
                    seen[l].push(state_bits(&state.lane(l).unwrap()));
                }
            }
        },
    );
    for l in 0..L {
        let (want, out) = single(building, lanes.single(), steps[l], |n| {
            ground(l, n, nan_lane)
        });
        assert_eq!(outcome[l], out, "lane {l} of {L}");
        assert_eq!(seen[l].len(), want.len(), "lane {l} of {L}: steps taken");
        for (k, (got, want)) in seen[l].iter().zip(&want).enumerate() {
            assert_eq!(got, want, "lane {l} of {L}, step {}", k + 1);
        }
    }
    outcome
}

/// `L` lanes by `LaneStepper::step` against single steps: reports (iterations, residual,
/// correction, branch changes), errors, states and histories, every step, with a mask
/// that idles lane 1 on every third step.
fn step_matches<Lw: LaneLaw<f64>, const N: usize, const L: usize>(
    building: &ShearBuilding<f64, Lw, N>,
    settings: NewtonSettings<f64>,
    steps: u64,
) -> usize
where
    Lw::History: core::fmt::Debug,
{
    let lanes = LaneStepper::<f64, N, L>::new(scene::H, settings).unwrap();
    let zero = SVector::<f64, N>::zeros();
    let virgin = building.initial_history();
    let start = lanes
        .single()
        .start_with_history(building, &zero, &zero, &zero, &virgin)
        .unwrap();
    let mut singles: [(State<f64, N>, [Lw::History; N]); L] = [start; L];
    let mut state = LaneState::from_states(&[start.0; L]);
    let mut history = core::array::from_fn(|i| [start.1[i]; L]);
    let mut errors = 0;
    for n in 1..=steps {
        let ag: [f64; L] = core::array::from_fn(|l| ground(l, n, 2));
        let active: [bool; L] = core::array::from_fn(|l| !(l == 1 && n % 3 == 0));
        let p = LaneStepper::<f64, N, L>::ground_loads(building, &ag);
        let reports = lanes.step(building, &mut state, &mut history, &p, active);
        for l in 0..L {
            if !active[l] {
                assert!(reports[l].is_none());
                continue;
            }
            let (s, h) = &mut singles[l];
            let want: Result<NewtonReport<f64>, Error> =
                lanes
                    .single()
                    .try_step_with_history(building, s, h, &building.ground_load(ag[l]));
            let got = reports[l].unwrap();
            errors += usize::from(got.is_err());
            match (got, want) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(
                        (a.iterations, a.converged, a.branch_changes),
                        (b.iterations, b.converged, b.branch_changes)
                    );
                    assert_eq!(
                        a.residual.to_bits(),
                        b.residual.to_bits(),
                        "step {n} lane {l}"
                    );
                    assert_eq!(a.correction.to_bits(), b.correction.to_bits());
                }
                (a, b) => assert_eq!(a, b, "step {n} lane {l}"),
            }
            let lane_h: [Lw::History; N] = core::array::from_fn(|i| history[i][l]);
            assert_eq!(
                bits_of(&state.lane(l).unwrap(), &lane_h),
                bits_of(s, h),
                "step {n} lane {l}"
            );
        }
    }
    errors
}

/// The benchmark IDA building (5 bilinear storeys, Rayleigh damping: the banded path).
fn bilinear() -> scene::Building {
    scene::building().unwrap()
}

/// The IDA settings (up to 50 iterations to 1e-12): every lane but the NaN one completes,
/// at L = 1, 2, 3, 4, 8, lengths 900 … 221 steps.
#[test]
fn lanes_are_single_analyses_bit_for_bit() {
    let b = bilinear();
    let s = scene::stepper().unwrap().settings();
    let out1 = run_matches::<_, 5, 1>(&b, s, 9);
    assert!(out1[0].is_ok());
    assert!(run_matches::<_, 5, 2>(&b, s, 9).iter().all(|o| o.is_ok()));
    let out = run_matches::<_, 5, 3>(&b, s, 2);
    assert_eq!(
        out[2],
        Err(Failure {
            step: 333,
            error: Error::NonFiniteInput
        })
    );
    assert!(run_matches::<_, 5, 4>(&b, s, 2)[2].is_err());
    let out = run_matches::<_, 5, 8>(&b, s, 5);
    assert!(out.iter().enumerate().all(|(l, o)| o.is_ok() == (l != 5)));
}

/// A budget of one iteration: the lanes that yield (scale ≥ 3.5) fail with `NotConverged`
/// at the first step whose branch changes (at different steps), the others go on;
/// `Exactly(2)` iterates every lane twice.
#[test]
fn failing_lanes_leave_the_others_bit_for_bit() {
    let b = bilinear();
    let out = run_matches::<_, 5, 8>(&b, NewtonSettings::up_to(1, 1e-12), 99);
    let failed: Vec<_> = out.iter().filter_map(|o| o.err()).collect();
    assert!(failed.len() >= 2, "{out:?}");
    assert!(
        failed.iter().all(|f| f.error == Error::NotConverged),
        "{out:?}"
    );
    assert!(failed.iter().any(|f| f.step != failed[0].step), "{out:?}");
    assert!(out[0].is_ok() && out[1].is_ok(), "{out:?}");
    let errors = step_matches::<_, 5, 4>(&b, NewtonSettings::up_to(1, 1e-12), 1000);
    assert!(errors > 0);
    step_matches::<_, 5, 3>(&b, NewtonSettings::exactly(2, 1e-12), 1000);
}

/// Reports, errors and histories step by step, with an idle lane, at L = 1, 2, 4, 8.
#[test]
fn step_reports_match() {
    let b = bilinear();
    let s = scene::stepper().unwrap().settings();
    step_matches::<_, 5, 1>(&b, s, 300);
    step_matches::<_, 5, 2>(&b, s, 300);
    let errors = step_matches::<_, 5, 4>(&b, s, 1000);
    assert_eq!(errors, 1); // lane 2's NaN at step 333
    step_matches::<_, 5, 8>(&b, s, 1000);
}

/// The other laws the Python package exposes (Bouc–Wen; bilinear beside friction) go
/// lane by lane through the law, and a dense damping matrix through the single step:
/// the same bits.
#[test]
fn other_laws_and_dense_damping_match() {
    let (m, c, _k) = models::five_storey_building();
    let masses = models::floor_masses(&m);
    let k = models::FIVE_STOREY_STIFFNESS;
    let s = scene::stepper().unwrap().settings();
    let bw = BoucWen::<f64>::new(k, scene::FY, scene::ALPHA, 0.5, 0.5, 2.0).unwrap();
    let bouc_wen = ShearBuilding::new(masses, [bw; 5], &c).unwrap();
    step_matches::<_, 5, 4>(&bouc_wen, s, 250);
    let pf = Parallel(
        Bilinear::<f64>::new(k, scene::FY, scene::ALPHA).unwrap(),
        Friction::<f64>::new(2e5, 1e-3).unwrap(),
    );
    let parallel = ShearBuilding::new(masses, [pf; 5], &c).unwrap();
    step_matches::<_, 5, 3>(&parallel, s, 250);
    // C with a coupling beyond the band: the dense path, lane by lane.
    let mut dense = c;
    dense[0][4] = 1e3;
    dense[4][0] = 1e3;
    let law = Bilinear::<f64>::new(k, scene::FY, scene::ALPHA).unwrap();
    let building = ShearBuilding::new(masses, [law; 5], &dense).unwrap();
    step_matches::<_, 5, 2>(&building, s, 250);
}

/// The IDA records of the tests: El Centro from samples 0, 100, 200, cut to 300, 340,
/// 380 samples (1195 … 1515 steps), so the traces see different records of different
/// lengths in one batch.
#[cfg(feature = "std")]
fn ida_records() -> Vec<Vec<f64>> {
    [(0, 300), (100, 340), (200, 380)]
        .iter()
        .map(|&(a, k)| elcentro::AG_F64[a..a + k].to_vec())
        .collect()
}

/// Stripes in lanes (4 wide: a stripe's three records and the next stripe's first) give
/// the curves of the one-run stripes, bit for bit, on 1 and 2 threads; the collapses (by
/// the drift limit) and the NaN-free errors included.
#[cfg(feature = "std")]
#[test]
fn stripes_in_lanes_are_the_stripes() {
    use aemstep::ida::{Batching, Collapse, OnFailure, Plan};
    let b = bilinear();
    let single = scene::stepper().unwrap();
    let lanes = LaneStepper::<f64, 5, 4>::new(scene::H, single.settings()).unwrap();
    let records = ida_records();
    let ims = [0.5, 1.5, 2.5, 4.0, 8.0];
    let collapse = Collapse {
        edp: 0.2,
        on_failure: OnFailure::Collapse,
    };
    let one = |r: &Vec<f64>, im: f64| scene::peak_drift(&b, &single, r, im, scene::steps(r.len()));
    let batched = |jobs: &[(&Vec<f64>, f64)]| {
        let jobs: Vec<(&[f64], f64, u64)> = jobs
            .iter()
            .map(|&(r, im)| (r.as_slice(), im, scene::steps(r.len())))
            .collect();
        scene::peak_drifts(&b, &lanes, &jobs)
    };
    let want = aemstep::ida::stripes(&records, &ims, &collapse, 1, one, None).unwrap();
    let plan = Plan::Stripes {
        intensities: &ims,
        collapse,
    };
    assert!(want.iter().any(|c| c.collapse.is_some()));
    let pts: Vec<_> = want.iter().flat_map(|c| c.points.iter()).collect();
    assert!(pts.iter().any(|p| !p.collapsed && p.edp > 0.03), "{want:?}");
    for threads in [1, 2] {
        let how = Batching {
            width: 4,
            threads,
            progress: None,
        };
        let got = aemstep::ida::batched(&records, &plan, &how, batched).unwrap();
        assert_eq!(format!("{got:?}"), format!("{want:?}")); // `{:?}` of f64 round-trips
    }
}

/// Hunt-and-fill in lanes (2 records a group, each tracing its own intensities) gives the
/// curves of the one-run hunt-and-fill, bit for bit, and the same progress total.
#[cfg(feature = "std")]
#[test]
fn hunt_fill_in_lanes_is_the_hunt_fill() {
    use aemstep::ida::{Batching, Collapse, HuntFill, OnFailure, Plan};
    use std::sync::atomic::{AtomicUsize, Ordering};
    let b = bilinear();
    let single = scene::stepper().unwrap();
    let lanes = LaneStepper::<f64, 5, 2>::new(scene::H, single.settings()).unwrap();
    let records = ida_records();
    let settings = HuntFill {
        first: 1.0,
        step: 3.0,
        step_increment: 1.0,
        resolution: 0.5,
        runs: 6,
        collapse: Collapse {
            edp: 0.2,
            on_failure: OnFailure::Collapse,
        },
    };
    let one = |r: &Vec<f64>, im: f64| scene::peak_drift(&b, &single, r, im, scene::steps(r.len()));
    let batched = |jobs: &[(&Vec<f64>, f64)]| {
        let jobs: Vec<(&[f64], f64, u64)> = jobs
            .iter()
            .map(|&(r, im)| (r.as_slice(), im, scene::steps(r.len())))
            .collect();
        scene::peak_drifts(&b, &lanes, &jobs)
    };
    let want = aemstep::ida::hunt_fill(&records, &settings, 1, one, None).unwrap();
    assert!(want.iter().all(|c| c.collapse.is_some()), "{want:?}");
    let last = AtomicUsize::new(0);
    let progress = |done: usize, total: usize| {
        assert_eq!(total, 18);
        last.fetch_max(done, Ordering::Relaxed);
    };
    let how = Batching {
        width: 2,
        threads: 2,
        progress: Some(&progress),
    };
    let got = aemstep::ida::batched(&records, &Plan::HuntFill(settings), &how, batched).unwrap();
    assert_eq!(format!("{got:?}"), format!("{want:?}"));
    assert_eq!(last.load(Ordering::Relaxed), 18);
}
