//! Response spectra of a folder of ground-motion records on the host: CSV spectra and an
//! SVG plot; with `--tables`, the accuracy tables of `docs/spectrum.md` (Markdown on stdout).
//!
//! ```text
//! cargo run --release -p xtask --bin spectrum -- [--in data] [--out docs] [--tables]
//! ```
//!
//! Reads every `*.txt` (one sample a line, `#` header lines, one of them giving
//! `dt = <seconds> s`; samples in g, like `data/elcentro-ns-1940.txt`) and every PEER
//! `*.AT2` (4 header lines, the 4th `NPTS= n, DT= dt SEC`, then samples in g, any number a
//! line) in the input folder. For each record: the 5 %-damped spectrum at 100 periods
//! log-spaced from 0.01 s to 10 s (`Bank<f64, 100>`, exact scheme, default sub-steps, free
//! vibration for one longest period after the record), all records at once on every core
//! (`spectrum::batch`). Writes `<out>/spectrum-<record>.csv` (T, ζ, Sd, Sv, Sa, PSV, PSA in
//! m, m/s, m/s²) and `<out>/spectrum.svg` (PSA against T).
//!
//! `--linear-sd` prints El Centro's Sd (m) at 100 periods spaced linearly from 0.01 s to
//! 10 s (those `sdof.spectrum` takes on its C path), one line per scheme: the AEM without
//! sub-steps, then the exact scheme with the default rule (`scripts/bench_spectrum.py`
//! compares them with `sdof`).
//!
//! `--tables` prints, for El Centro: the peak error against the sub-step count, the
//! sub-step rule's error and cost, the free vibration after the record, and the schemes and
//! `f32` against the converged spectrum (every number computed here).

use std::error::Error as StdError;
use std::fs;
use std::path::{Path, PathBuf};

use aemstep::spectrum::{Bank, MAX_SUBSTEPS, Response, Scheme, Substeps, batch};
use plotters::prelude::*;

const G: f64 = 9.80665;
const P: usize = 100;
const ZETA: f64 = 0.05;

type Res<T> = Result<T, Box<dyn StdError>>;

/// A record: name, sample interval (s), ground acceleration (m/s²).
struct Record {
    name: String,
    dt: f64,
    ag: Vec<f64>,
}

fn periods() -> [f64; P] {
    core::array::from_fn(|i| 0.01 * 1000f64.powf(i as f64 / (P - 1) as f64))
}

/// One-column text: `#` header lines (one with `dt = <x> s`), samples in g.
fn read_txt(path: &Path) -> Res<Record> {
    let text = fs::read_to_string(path)?;
    let mut dt = None;
    let mut ag = Vec::new();
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
        if let Some(h) = line.strip_prefix('#') {
            if let Some(rest) = h.split("dt =").nth(1) {
                dt = rest
                    .split_whitespace()
                    .next()
                    .and_then(|x| x.parse::<f64>().ok());
            }
            continue;
        }
        ag.push(line.parse::<f64>()? * G);
    }
    Ok(Record {
        name: stem(path),
        dt: dt.ok_or_else(|| format!("{}: no `dt = <x> s` header line", path.display()))?,
        ag,
    })
}

/// PEER `.AT2`: 3 free header lines, then `NPTS= n, DT= dt SEC`, then samples in g.
fn read_at2(path: &Path) -> Res<Record> {
    let text = fs::read_to_string(path)?;
    let mut lines = text.lines();
    let head = lines.by_ref().take(4).collect::<Vec<_>>();
    let h4 = head
        .get(3)
        .ok_or("AT2: fewer than 4 header lines")?
        .to_uppercase();
    let field = |key: &str| -> Res<f64> {
        let rest = h4
            .split(key)
            .nth(1)
            .ok_or(format!("AT2: no {key} in '{h4}'"))?;
        let tok = rest
            .trim_start_matches(['=', ' '])
            .split([',', ' '])
            .next()
            .unwrap_or("");
        Ok(tok.parse::<f64>()?)
    };
    let (npts, dt) = (field("NPTS")? as usize, field("DT")?);
    let ag: Vec<f64> = lines
        .flat_map(str::split_whitespace)
        .map(|x| x.parse::<f64>().map(|a| a * G))
        .collect::<Result<_, _>>()?;
    if ag.len() != npts {
        return Err(format!("{}: NPTS = {npts} but {} samples", path.display(), ag.len()).into());
    }
    Ok(Record {
        name: stem(path),
        dt,
        ag,
    })
}

fn stem(p: &Path) -> String {
    let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
    format!(
        "{}-{}",
        p.file_stem().and_then(|s| s.to_str()).unwrap_or("record"),
        ext.to_lowercase()
    )
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |k: &str, d: &str| {
        args.iter()
            .position(|a| a == k)
            .and_then(|i| args.get(i + 1))
            .cloned()
            .unwrap_or(d.into())
    };
    if args.iter().any(|a| a == "--tables") {
        return tables();
    }
    if args.iter().any(|a| a == "--linear-sd") {
        return linear_sd();
    }
    let (input, out) = (
        PathBuf::from(arg("--in", "data")),
        PathBuf::from(arg("--out", "docs")),
    );
    let mut paths: Vec<PathBuf> = fs::read_dir(&input)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    paths.sort();
    let mut records = Vec::new();
    for p in &paths {
        match p
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_lowercase)
            .as_deref()
        {
            Some("txt") => records.push(read_txt(p)?),
            Some("at2") => records.push(read_at2(p)?),
            _ => {}
        }
    }
    if records.is_empty() {
        return Err(format!("no .txt or .AT2 record in {}", input.display()).into());
    }
    fs::create_dir_all(&out)?;
    // one bank per sample interval; all records of that interval in one batch
    let mut dts: Vec<f64> = records.iter().map(|r| r.dt).collect();
    dts.sort_by(f64::total_cmp);
    dts.dedup();
    let mut spectra: Vec<(usize, Bank<f64, P>, Response<f64, P>)> = Vec::new();
    for dt in dts {
        let bank = Bank::<f64, P>::new(periods(), [ZETA; P], dt)?;
        let idx: Vec<usize> = (0..records.len())
            .filter(|&i| records[i].dt == dt)
            .collect();
        let slices: Vec<&[f64]> = idx.iter().map(|&i| records[i].ag.as_slice()).collect();
        let t0 = std::time::Instant::now();
        let out = batch::spectra(&bank, &slices, bank.free_vibration_samples(), 0)
            .into_iter()
            .collect::<Result<Vec<_>, _>>()?;
        eprintln!(
            "dt = {dt} s: {} record(s) in {:.2?} (host)",
            idx.len(),
            t0.elapsed()
        );
        spectra.extend(idx.into_iter().zip(out).map(|(i, r)| (i, bank, r)));
    }
    spectra.sort_by_key(|s| s.0);
    for (i, bank, r) in &spectra {
        let rec = &records[*i];
        let path = out.join(format!("spectrum-{}.csv", rec.name));
        let (psv, psa) = (bank.psv(r.sd()), bank.psa(r.sd()));
        let mut csv =
            String::from("period_s,damping,sd_m,sv_m_per_s,sa_m_per_s2,psv_m_per_s,psa_m_per_s2\n");
        for p in 0..P {
            csv += &format!(
                "{},{},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e}\n",
                bank.periods()[p],
                bank.damping()[p],
                r.sd()[p],
                r.sv()[p],
                r.sa()[p],
                psv[p],
                psa[p]
            );
        }
        fs::write(&path, csv)?;
        println!(
            "{}: {} samples at {} s, {} skipped -> {}",
            rec.name,
            r.samples(),
            rec.dt,
            r.skipped(),
            path.display()
        );
    }
    let svg = out.join("spectrum.svg");
    plot(&svg, &records, &spectra)?;
    println!("plot -> {}", svg.display());
    Ok(())
}

fn plot(
    path: &Path,
    records: &[Record],
    spectra: &[(usize, Bank<f64, P>, Response<f64, P>)],
) -> Res<()> {
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let ymax = spectra
        .iter()
        .flat_map(|(_, b, r)| b.psa(r.sd()))
        .fold(0.0, f64::max);
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Pseudo-spectral acceleration, 5 % damping (aemstep::spectrum, exact scheme)",
            ("sans-serif", 18),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d((0.01f64..10.0).log_scale(), 0.0..ymax * 1.1)?;
    chart
        .configure_mesh()
        .x_desc("period T (s)")
        .y_desc("PSA (m/s²)")
        .x_label_formatter(&|x| format!("{x}"))
        .draw()?;
    for (k, (i, b, r)) in spectra.iter().enumerate() {
        let col = Palette99::pick(k);
        let pts: Vec<(f64, f64)> = b.periods().iter().copied().zip(b.psa(r.sd())).collect();
        let width = if k == 0 { 4 } else { 1 };
        chart
            .draw_series(LineSeries::new(pts, col.stroke_width(width)))?
            .label(records[*i].name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

fn linear_sd() -> Res<()> {
    let rec = elcentro()?;
    let per: [f64; P] = core::array::from_fn(|i| 0.01 + (10.0 - 0.01) * i as f64 / (P - 1) as f64);
    for (s, n) in [
        (Scheme::Aem, Substeps::Fixed(1)),
        (Scheme::Exact, Substeps::AUTO),
    ] {
        let b = Bank::<f64, P>::with(per, [ZETA; P], rec.dt, s, n)?;
        let r = run(&b, &rec.ag, 0);
        println!(
            "{}",
            r.sd()
                .iter()
                .map(|x| format!("{x:e}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------
// --tables

fn elcentro() -> Res<Record> {
    read_txt(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../data/elcentro-ns-1940.txt"
    )))
}

fn run(b: &Bank<f64, P>, ag: &[f64], free: u32) -> Response<f64, P> {
    let mut r = b.at_rest();
    for &a in ag {
        b.step(&mut r, a);
    }
    b.free_vibration(&mut r, free);
    r
}

/// Largest relative error of Sd, Sv, Sa over the periods selected by `keep`.
fn worst(
    r: &Response<f64, P>,
    reference: &Response<f64, P>,
    keep: impl Fn(usize) -> bool,
) -> [f64; 3] {
    let mut w = [0.0f64; 3];
    for p in (0..P).filter(|&p| keep(p)) {
        let rel = |a: f64, b: f64| (a - b).abs() / b;
        w[0] = w[0].max(rel(r.sd()[p], reference.sd()[p]));
        w[1] = w[1].max(rel(r.sv()[p], reference.sv()[p]));
        w[2] = w[2].max(rel(r.sa()[p], reference.sa()[p]));
    }
    w
}

fn pct(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if x >= 0.001 {
        format!("{:.2}", 100.0 * x)
    } else {
        format!("{:.1e}", 100.0 * x)
    }
}

fn tables() -> Res<()> {
    let rec = elcentro()?;
    let dt = rec.dt;
    let per = periods();
    let bank = |s: Scheme, n: Substeps| Bank::<f64, P>::with(per, [ZETA; P], dt, s, n);
    let converged = run(
        &bank(Scheme::Exact, Substeps::Fixed(MAX_SUBSTEPS))?,
        &rec.ag,
        0,
    );
    println!("## Short periods: peak error against the sub-step count\n");
    println!(
        "El Centro NS 1940 ({} samples, dt = {dt} s), 5 % damping, 100 periods log-spaced 0.01–10 s, exact scheme, \
         every oscillator with the same sub-step count n. Largest relative error (%) of Sd / Sv / Sa over the periods \
         in each band of T/dt, against the converged peaks (n = {MAX_SUBSTEPS}: at least {} points a period). \
         Generated by `cargo run --release -p xtask --bin spectrum -- --tables`.\n",
        rec.ag.len(),
        (MAX_SUBSTEPS as f64 * 0.01 / dt) as u32
    );
    let bands = [
        (0.5, 1.0),
        (1.0, 2.0),
        (2.0, 5.0),
        (5.0, 10.0),
        (10.0, 20.0),
        (20.0, 501.0),
    ];
    let mut head = String::from("| n |");
    let mut rule = String::from("|---:|");
    for (lo, hi) in bands {
        head += &format!(" {lo} ≤ T/dt < {hi} |");
        rule += "---|";
    }
    println!("{head}\n{rule}");
    for n in [1u16, 2, 3, 4, 6, 8, 12, 16, 32] {
        let r = run(&bank(Scheme::Exact, Substeps::Fixed(n))?, &rec.ag, 0);
        let mut line = format!("| {n} |");
        for (lo, hi) in bands {
            let w = worst(&r, &converged, |p| per[p] / dt >= lo && per[p] / dt < hi);
            line += &format!(" {} / {} / {} |", pct(w[0]), pct(w[1]), pct(w[2]));
        }
        println!("{line}");
    }
    println!("\n## The sub-step rule\n");
    println!(
        "Rule `Substeps::PointsPerPeriod(r)`: n_p = ⌈r·dt/T_p⌉ (at least r points a period where the peak is taken). \
         Largest relative error (%) over all 100 periods, against the converged peaks, and the sub-steps a sample \
         would cost if every interval were walked (Σ n_p; the bank walks them only where its bound says a peak can \
         rise, see `Bank::step`).\n"
    );
    println!("| r | Σ n_p | Sd | Sv | Sa |\n|---:|---:|---:|---:|---:|");
    for r in [1u16, 2, 5, 10, 15, 20, 30, 40] {
        let b = bank(Scheme::Exact, Substeps::PointsPerPeriod(r))?;
        let w = worst(&run(&b, &rec.ag, 0), &converged, |_| true);
        let mark = if Substeps::PointsPerPeriod(r) == Substeps::AUTO {
            " (default)"
        } else {
            ""
        };
        println!(
            "| {r}{mark} | {} | {} | {} | {} |",
            b.substeps_per_sample(),
            pct(w[0]),
            pct(w[1]),
            pct(w[2])
        );
    }
    let b = bank(Scheme::Exact, Substeps::AUTO)?;
    let r = run(&b, &rec.ag, 0);
    let candidates =
        b.substeps().iter().filter(|&&n| n > 1).count() as u64 * (rec.ag.len() as u64 - 1);
    println!(
        "\nWith the default rule the bank walked {} of the {candidates} (oscillator, interval) pairs with n_p > 1 \
         ({} %): the bound of `Bank::step` leaves the sub-steps out wherever no peak can rise.",
        r.walks(),
        pct(r.walks() as f64 / candidates as f64)
    );
    println!(
        "\nChosen: r = 20, the smallest in this table with every peak (Sd, Sa) within 1 % and Sv within 1.5 %. \
         `tests/spectrum.rs` (`substep_rule_meets_its_criterion`) checks it.\n"
    );

    println!("## Long periods: free vibration after the record\n");
    let b = bank(Scheme::Exact, Substeps::AUTO)?;
    let fv = b.free_vibration_samples();
    println!(
        "`Bank::free_vibration(r, b.free_vibration_samples())` continues with zero ground acceleration for one period of \
         the longest oscillator ({fv} samples = {} s here); ten times longer changes no peak (`free_vibration_after_the_record`).\n",
        fv as f64 * dt
    );
    println!(
        "| record | periods whose Sd rises | from T (s) | largest rise of Sd |\n|---|---:|---:|---:|"
    );
    for (name, len) in [
        ("El Centro, whole (80 s)", rec.ag.len()),
        ("El Centro, first 5 s", 251),
    ] {
        let a = run(&b, &rec.ag[..len], 0);
        let f = run(&b, &rec.ag[..len], fv);
        let up: Vec<usize> = (0..P).filter(|&p| f.sd()[p] > a.sd()[p]).collect();
        let most = up
            .iter()
            .map(|&p| f.sd()[p] / a.sd()[p] - 1.0)
            .fold(0.0, f64::max);
        let from = up.first().map_or("–".into(), |&p| format!("{:.3}", per[p]));
        println!("| {name} | {} | {from} | {} % |", up.len(), pct(most));
    }

    println!("\n## Schemes and precision against the converged spectrum\n");
    println!(
        "Largest relative error (%) over the 100 periods (exact scheme, n = {MAX_SUBSTEPS}, as the reference).\n"
    );
    println!("| scheme | sub-steps | type | Sd | Sv | Sa |\n|---|---|---|---:|---:|---:|");
    for (sname, s) in [("exact", Scheme::Exact), ("AEM", Scheme::Aem)] {
        for (nname, n) in [
            ("default rule", Substeps::AUTO),
            ("none (n = 1)", Substeps::Fixed(1)),
        ] {
            let w = worst(&run(&bank(s, n)?, &rec.ag, 0), &converged, |_| true);
            println!(
                "| {sname} | {nname} | f64 | {} | {} | {} |",
                pct(w[0]),
                pct(w[1]),
                pct(w[2])
            );
        }
    }
    let b32 = Bank::<f32, P>::new(per, [ZETA; P], dt)?;
    let mut r32 = b32.at_rest();
    for &a in &rec.ag {
        b32.step(&mut r32, a as f32);
    }
    let r64 = run(&b, &rec.ag, 0);
    let mut w = [0.0f64; 3];
    for p in 0..P {
        let rel = |a: f32, b: f64| (a as f64 - b).abs() / b;
        w[0] = w[0].max(rel(r32.sd()[p], r64.sd()[p]));
        w[1] = w[1].max(rel(r32.sv()[p], r64.sv()[p]));
        w[2] = w[2].max(rel(r32.sa()[p], r64.sa()[p]));
    }
    println!(
        "\n`f32` against `f64` (same scheme and rule): largest relative difference {} / {} / {} % (Sd / Sv / Sa).",
        pct(w[0]),
        pct(w[1]),
        pct(w[2])
    );
    Ok(())
}
