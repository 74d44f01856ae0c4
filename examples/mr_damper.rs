//! An MR damper (Dyke et al. 1996 Bouc–Wen, `MrParameters::DYKE_1996`) between the ground
//! and floor 1 of the 3-storey benchmark model under El Centro NS at five times its rate,
//! switched by clipped-optimal control: an LQG controller at 1 kHz on the three absolute
//! floor accelerations and the measured damper force. Prints the peak drifts (cm) and
//! damper force (N). `cargo run --release --example mr_damper [record.txt]` (one value in g
//! per line, dt = 0.02 s; default `data/elcentro-ns-1940.txt`). Full table: docs/control.md.
use aemstep::NewtonSettings;
use aemstep::control::{ClippedOptimal, Controller, Coupled, DesignModel, LinearStructure};
use aemstep::control::{Link, Lqr, MrDamper, MrParameters, Weights};
use aemstep::hysteresis::HistoryModel;
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::observer::{Observer, Outputs, StateSpace, SteadyState};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/data/elcentro-ns-1940.txt").into()
    });
    let rec: Vec<f64> = std::fs::read_to_string(&path)?
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| l.trim().parse::<f64>().map(|g| g * 9.80665))
        .collect::<Result<_, _>>()?;
    let (m, h, dt) = (98.3, 1e-3, 0.02 * 0.2); // kg a floor, controller = plant step (s), record step (s)
    let mm = [[m, 0.0, 0.0], [0.0, m, 0.0], [0.0, 0.0, m]];
    let k = [
        [12.0e5, -6.84e5, 0.0],
        [-6.84e5, 13.7e5, -6.84e5],
        [0.0, -6.84e5, 6.84e5],
    ]; // N/m
    let c = [
        [175.0, -50.0, 0.0],
        [-50.0, 100.0, -50.0],
        [0.0, -50.0, 50.0],
    ]; // N·s/m
    let mat = |r: [[f64; 3]; 3]| SMatrix::<f64, 3, 3>::from_fn(|i, j| r[i][j]);
    let zoh = |b: [f64; 3]| {
        StateSpace::<3, 6, 1>::zero_order_hold(
            &mat(mm),
            &mat(c),
            &mat(k),
            &SMatrix::from_column_slice(&b),
            h,
        )
    };
    let (ss, ground) = (zoh([-1.0, 0.0, 0.0])?, zoh([-m; 3])?); // damper force f on floor 1 as −f
    let mut q = [[0.0; 6]; 6];
    (0..3).for_each(|i| q[i][i] = 1e7); // on the floor displacements (1/m²), R = 1e-3 (1/N²)
    let lqr = Lqr::from_parts(
        &DesignModel::from_state_space(&ss).delayed::<7>()?,
        &Weights::new(&q, &[[1e-3]]).delayed::<7>(&[[1e-6]])?,
    )?;
    let sensors = ss.outputs(&Outputs::accelerations(Outputs::<3, 1, 3>::select([
        0, 1, 2,
    ])))?;
    let qn = SMatrix::<f64, 6, 6>::from_fn(|i, j| {
        ground.input_noise(&[[1e3]])[i][j] + if i == j { 1e-14 } else { 0.0 }
    });
    let kf = SteadyState::new(
        &ss,
        &sensors,
        &qn,
        &(SMatrix::<f64, 3, 3>::identity() * 10.0),
    )?;
    let ctl = Controller::new(
        Observer::new(&ss, &sensors, &kf.gain_matrix())?,
        &lqr.gain_matrix(),
        &[1e5],
    )?;
    let law = ClippedOptimal::<f64, 1>::new(MrParameters::DYKE_1996.v_max)?;
    let damper = MrDamper::new(&MrParameters::DYKE_1996)?;
    let mut model = Coupled::passive_off(
        LinearStructure::new(&mm, &c, &k)?,
        damper,
        Link::Ground(0),
        h,
    )?;
    let stepper = model.nonlinear(NewtonSettings::default())?;
    let ag = |t: f64| {
        let (s, i) = (t / dt, (t / dt) as usize);
        if i + 1 < rec.len() {
            rec[i] + (s - i as f64) * (rec[i + 1] - rec[i])
        } else {
            0.0
        }
    };
    let (zero, h0) = (SVector::zeros(), model.initial_history());
    let (mut s, mut hist) = stepper.start_with_history(
        &model,
        &zero,
        &zero,
        &SVector::from_element(-m * ag(0.0)),
        &h0,
    )?;
    let (mut cs, mut pending, mut drift, mut force) =
        (ctl.start_at_rest(), 0.0, [0.0f64; 3], 0.0f64);
    for n in 0..((rec.len() as f64 * dt + 1.0) / h) as usize {
        let (t, f) = (n as f64 * h, model.delivered_force(&hist)); // f: the measured force (N)
        model.set_command(pending)?; // the voltage computed at the last sample (V)
        let y = s.a().map(|a| a + ag(t)); // absolute accelerations (m/s²)
        let fc = ctl.try_step(&mut cs, &y, &SVector::from([f]), false)?.force[0]; // desired (N)
        pending = law.command(&SVector::from([fc]), &SVector::from([f]))?[0];
        stepper.try_step_with_history(
            &model,
            &mut s,
            &mut hist,
            &SVector::from_element(-m * ag(t + h)),
        )?;
        (0..3).for_each(|i| {
            drift[i] = drift[i].max((s.u()[i] - if i > 0 { s.u()[i - 1] } else { 0.0 }).abs())
        });
        force = force.max(model.delivered_force(&hist).abs());
    }
    println!(
        "clipped-optimal MR damper, controller at 1 kHz: peak drift (cm) {:.3} {:.3} {:.3}, peak damper force (N) {force:.0}",
        100.0 * drift[0],
        100.0 * drift[1],
        100.0 * drift[2]
    );
    Ok(())
}
