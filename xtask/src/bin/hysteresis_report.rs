//! Writes `docs/hysteresis_figures.md` (to stdout): every measured figure of the
//! hysteresis work — each law against a closed form and an independent implementation,
//! the yielding 3-storey building under El Centro at halving time steps (energy closure,
//! convergence orders, Newton iterations, branch changes), and the host twin of the
//! firmware (f32, fixed iterations, against f64). Deterministic IEEE arithmetic, no timing.
//!
//! Run: `cargo run --release -p xtask --bin hysteresis_report` (`python3 scripts/check_docs.py
//! --write` writes the page; the test command regenerates and compares it).

#[path = "../../../scenes/hysteretic/building.rs"]
mod building;
#[path = "../../../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../../../tests/support/hyst.rs"]
mod hyst;
#[path = "../../../tests/support/laws.rs"]
mod laws;

use aemstep::NewtonSettings;

fn list(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.2e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn ords(v: &[f64]) -> String {
    laws::orders(v)
        .iter()
        .map(|x| format!("{x:.2}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn main() {
    println!("# Hysteresis: measured figures\n");
    println!(
        "Produced by `cargo run --release -p xtask --bin hysteresis_report` (deterministic IEEE \
         arithmetic, no timing). Generated page: `python3 scripts/check_docs.py --write` writes \
         it; the test command regenerates it and fails when a number differs by more than one \
         unit in its last printed digit. Explained in [hysteresis.md](hysteresis.md); \
         `tests/hysteresis.rs` asserts on each figure.\n"
    );

    println!("## Each law against a closed form or an independent implementation\n");
    println!(
        "Laws with k = 1e8 N/m, f_y = 5e5 N, α = 0.05; cycles d = U sin 2πt. Loop figures: the \
         worst relative error over 16 amplitudes U in [3u_y, 4u_y), at 64, 128, 256, 512 steps \
         a cycle.\n"
    );
    println!("| figure | errors | orders |");
    println!("|---|---|---|");
    let (bil, bil_ratio) = laws::bilinear_loop();
    println!(
        "| bilinear cycle work vs 4 f_y (1 − α)(U − u_y) | {} | {} |",
        list(&bil),
        ords(&bil)
    );
    let (bw, bw_ratio) = laws::bouc_wen_loop();
    println!(
        "| Bouc–Wen (β = γ = 0.5, n = 1) cycle work vs its closed-form steady loop | {} | {} |",
        list(&bw),
        ords(&bw)
    );
    for (b, g, n) in laws::RK4_SHAPES {
        let e = laws::bouc_wen_rk4(b, g, n);
        println!(
            "| Bouc–Wen (β = {b}, γ = {g}, n = {n}) z vs RK4 in time, 64, 128, 256 steps a cycle | {} | {} |",
            list(&e),
            ords(&e)
        );
    }
    let (closed, fr) = laws::friction_cycle();
    println!(
        "| friction (f_s = 2e4 N, v_r = 1e-3 m/s, U = 0.01 m) cycle work vs {closed:.6e} J, 1000, 2000, 4000 steps a cycle (J) | {} | {} |",
        list(&fr),
        ords(&fr)
    );
    println!(
        "\nWorst error over its derived bound (1 − α) k Δ²/2, bilinear: {bil_ratio:.3}. Worst \
         Bouc–Wen loop error over the scale (2πU/m)² f_y/u_y: {bw_ratio:.3}.\n"
    );

    println!("## The yielding building under El Centro\n");
    println!(
        "3 storeys (scenes/hysteretic/building.rs), the whole record, Newton to 1e-12; \
         closure = max over the run of |E_in − (E_k + E_s + E_v + E_h)| / max E_in.\n"
    );
    let rs = [1u64, 2, 4, 8, 16, 32];
    for (name, run) in [
        ("bilinear", hyst::bilinear_run as fn(u64) -> hyst::Run),
        ("Bouc–Wen (β = γ = 0.5, n = 2)", hyst::bouc_wen_run),
    ] {
        let runs: Vec<hyst::Run> = rs.iter().map(|&r| run(r)).collect();
        println!("### {name} storeys\n");
        for line in hyst::table(&rs, &runs) {
            println!("{line}");
        }
        let worst = runs.iter().map(|r| r.discrete_closure).fold(0.0, f64::max);
        println!(
            "\nThe scheme's own discrete energy balance ({name}) closes to {worst:.1e} of max E_in or better at every h.\n"
        );
    }

    println!("## The firmware's host twin\n");
    let (r64, _, _) = hyst::roof::<f64>(NewtonSettings::up_to(30, 1e-12), &elcentro::AG_F64);
    let (r32, _, unconverged) =
        hyst::roof::<f32>(NewtonSettings::exactly(3, 1.5e-5), &elcentro::AG_F32);
    let worst = r32
        .iter()
        .zip(&r64)
        .step_by(10)
        .map(|(a, b)| (a - (*b as f32) as f64).abs())
        .fold(0.0, f64::max);
    let peak = r64.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    println!(
        "Bilinear building, h = 0.02 s, f32 with exactly 3 Newton iterations ({unconverged} steps unconverged) against the f64 run: max |roof f32 − roof f64| at every 10th step = {worst:.3e} m, peak roof displacement {peak:.3e} m."
    );
}
