//! SVG charts (issue 4 acceptance): the files are well-formed SVG (parsed with an XML parser) and
//! hold the expected series: one curve and one legend entry per contact or apple, several runs
//! on one chart, axes with units.

use crate::common;
use applesim::output::plot::{self, PlotOptions};
use common::*;
use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// The Fig. 1 apple dropped at `v0` into run folder `dir`.
fn drop_run(v0: f64, dir: &Path) {
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.apples[0].velocity_m_s = [0.0, 0.0, -v0];
    applesim::run::to_dir(&sc, &repo("scenarios"), dir, &mut |_| {}).unwrap();
}

struct Svg {
    texts: Vec<String>,
    /// (stroke colour, points) of every polyline.
    lines: Vec<(String, Vec<(f64, f64)>)>,
}

fn read_svg(path: &Path) -> Svg {
    let text = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&text)
        .unwrap_or_else(|e| panic!("{} is not well-formed XML: {e}", path.display()));
    assert!(doc.root_element().has_tag_name("svg"), "root is not <svg>");
    let texts = doc
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter_map(|n| n.text().map(|t| t.trim().to_string()))
        .collect();
    let lines = doc
        .descendants()
        .filter(|n| n.has_tag_name("polyline"))
        .map(|n| {
            let pts = n
                .attribute("points")
                .unwrap()
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect();
            (n.attribute("stroke").unwrap_or("").to_string(), pts)
        })
        .collect();
    Svg { texts, lines }
}

/// The data curve of a colour: its longest polyline (the legend sample is 2 points).
fn curve<'a>(svg: &'a Svg, colour: &str) -> &'a [(f64, f64)] {
    svg.lines
        .iter()
        .filter(|l| l.0.eq_ignore_ascii_case(colour))
        .max_by_key(|l| l.1.len())
        .map(|l| l.1.as_slice())
        .unwrap_or(&[])
}

#[test]
fn several_runs_on_one_force_chart_and_velocity_charts() {
    let root = tmp("plots");
    let runs = [root.join("v0.6"), root.join("v1.4")];
    drop_run(0.6, &runs[0]);
    drop_run(1.4, &runs[1]);
    let out = root.join("charts");
    let s = plot::plot_runs(&runs, &out, &PlotOptions::default()).unwrap();
    // Force, speed, spin, and the slip chart (bodies.csv has slip_m_s); no rolling-start
    // histogram: a plane has no running direction.
    assert_eq!(s.written.len(), 4, "{:?}", s.written);
    assert!(s.written.contains(&out.join(plot::SLIP_CHART)));

    let f = read_svg(&out.join(plot::FORCE_CHART));
    for t in [
        "time since first touch (ms)",
        "normal force P (N)",
        "Normal contact force",
    ] {
        assert!(
            f.texts.iter().any(|x| x == t),
            "missing text '{t}' in {:?}",
            f.texts
        );
    }
    // Legend: one entry per run and contact, with the peak force (37.30 N and 100.04 N: golden
    // values of these runs; the 1.4 m/s drop is checked against RK4 in tests/shipped_scenarios.rs).
    let legend: Vec<&String> = f.texts.iter().filter(|t| t.contains(" - floor")).collect();
    println!("force legend {legend:?}");
    assert_eq!(legend.len(), 2);
    assert!(
        legend[0].starts_with("v0.6: a1 - floor (37."),
        "{}",
        legend[0]
    );
    assert!(
        legend[1].starts_with("v1.4: a1 - floor (100."),
        "{}",
        legend[1]
    );
    // One curve per run in the first two palette colours, each a whole pulse (hundreds of
    // points); the faster impact peaks higher (smaller y in SVG coordinates).
    let slow = curve(&f, "#1F77B4");
    let fast = curve(&f, "#FF7F0E");
    println!("curve points: {} and {}", slow.len(), fast.len());
    assert!(slow.len() > 200 && fast.len() > 200);
    let top = |c: &[(f64, f64)]| c.iter().map(|p| p.1).fold(f64::MAX, f64::min);
    let base = |c: &[(f64, f64)]| c.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    assert!(top(fast) < top(slow));
    // Both start and end on the zero line: the touch and parting instants are drawn.
    assert_eq!(slow.first().unwrap().1, base(slow));
    assert_eq!(fast.last().unwrap().1, base(fast));
    // The peaks scale as the impacts do: the ratio of the two peak forces from an independent RK4
    // integration of each drop (elastic Hertz with gravity, touching after 0.1 mm of free fall;
    // tests/common/ode.rs), read off the pixels within 3 % (the chart's resolution). Without
    // gravity it would be the closed form (1.4 / 0.6)^1.2 = 2.76; gravity makes it 2.68.
    let rk4_peak = |v0: f64| {
        common::ode::Setup {
            mass_kg: 0.107,
            k: common::ode::fig1_k(),
            r_star_m: 0.04,
            ke: 1.0,
            lambda_s_m: 1000.0,
            g_n: 9.81,
        }
        .impact((v0 * v0 + 2.0 * 9.81 * 1e-4).sqrt(), 0.1)
        .peak_force_n
    };
    let want = rk4_peak(1.4) / rk4_peak(0.6);
    let ratio = (base(fast) - top(fast)) / (base(slow) - top(slow));
    println!("peak height ratio {ratio:.3}, RK4 {want:.3}");
    assert!(
        (ratio / want - 1.0).abs() < 0.03,
        "ratio {ratio}, RK4 {want}"
    );

    for (file, y) in [
        (plot::SPEED_CHART, "speed |v| (m/s)"),
        (plot::SPIN_CHART, "angular speed |w| (rad/s)"),
    ] {
        let v = read_svg(&out.join(file));
        assert!(v.texts.iter().any(|t| t == "time (s)"));
        assert!(v.texts.iter().any(|t| t == y), "{file}: {:?}", v.texts);
        assert!(v.texts.iter().any(|t| t == "v0.6: a1"));
        assert!(v.texts.iter().any(|t| t == "v1.4: a1"));
        // bodies.csv has 301 samples per run (3000 steps, every 10th, plus the end state).
        assert_eq!(curve(&v, "#1F77B4").len(), 301, "{file}");
        assert_eq!(curve(&v, "#FF7F0E").len(), 301, "{file}");
    }
}

#[test]
fn max_series_keeps_the_largest_peaks_and_says_so() {
    // Four apples dropped at 0.4, 1.0, 0.7 and 1.3 m/s in one run; two curves asked for.
    let mut sc = shipped("scenarios/drop_on_steel.json");
    let a0 = sc.apples[0].clone();
    sc.apples.clear();
    for (k, v) in [0.4, 1.0, 0.7, 1.3].into_iter().enumerate() {
        let mut a = a0.clone();
        a.name = format!("a{k}");
        a.position_m = [0.2 * k as f64, 0.0, 0.0401];
        a.velocity_m_s = [0.0, 0.0, -v];
        sc.apples.push(a);
    }
    let root = tmp("plots_max");
    let run = root.join("four");
    applesim::run::to_dir(&sc, &repo("scenarios"), &run, &mut |_| {}).unwrap();
    let out = root.join("charts");
    let opts = PlotOptions {
        max_series: 2,
        ..PlotOptions::default()
    };
    let s = plot::plot_runs(std::slice::from_ref(&run), &out, &opts).unwrap();
    println!("{:?}", s.notes);
    let f = read_svg(&out.join(plot::FORCE_CHART));
    let legend: Vec<&String> = f.texts.iter().filter(|t| t.contains(" - floor")).collect();
    println!("{legend:?}");
    // The two fastest drops (a3 at 1.3 m/s, a1 at 1.0 m/s), in contact order: a3 touches first.
    assert_eq!(legend.len(), 2);
    assert!(legend[0].starts_with("a3 - floor") && legend[1].starts_with("a1 - floor"));
    assert!(s.notes.iter().any(|n| n.contains("2 of 4 contacts drawn")));
    assert!(s.notes.iter().any(|n| n.contains("2 of 4 apples drawn")));
    // --apple picks apples by name.
    let opts = PlotOptions {
        apples: vec!["a2".into()],
        ..PlotOptions::default()
    };
    plot::plot_runs(std::slice::from_ref(&run), &out, &opts).unwrap();
    let v = read_svg(&out.join(plot::SPEED_CHART));
    assert!(v.texts.iter().any(|t| t == "a2") && !v.texts.iter().any(|t| t == "a1"));
}

#[test]
fn run_plots_flag_and_plot_command() {
    let bin = env!("CARGO_BIN_EXE_applesim");
    let dir = tmp("plots_cli");
    let st = std::process::Command::new(bin)
        .arg("run")
        .arg(repo("scenarios/slip_to_roll.json"))
        .arg("--out")
        .arg(&dir)
        .args(["--plots", "--quiet"])
        .status()
        .unwrap();
    assert!(st.success());
    for f in [plot::FORCE_CHART, plot::SPEED_CHART, plot::SPIN_CHART] {
        read_svg(&dir.join(f));
    }
    // Figs. 6-7: the spin grows from 0 to the rolling value 5/7 v0 / R = 8.93 rad/s and stays.
    let spin = read_svg(&dir.join(plot::SPIN_CHART));
    let c = curve(&spin, "#1F77B4");
    assert!(
        c.first().unwrap().1 > c.last().unwrap().1,
        "spin rises (SVG y grows downwards)"
    );
    let out = std::process::Command::new(bin)
        .arg("plot")
        .arg(&dir)
        .arg("--out")
        .arg(dir.join("again"))
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("linear_velocity.svg"));
    let missing = std::process::Command::new(bin)
        .args(["plot", "/nonexistent/run", "--out"])
        .arg(dir.join("x"))
        .output()
        .unwrap();
    assert_eq!(missing.status.code(), Some(1));
    let err = String::from_utf8_lossy(&missing.stderr);
    assert!(
        err.starts_with("error: /nonexistent/run/bodies.csv"),
        "{err}"
    );
}

#[test]
fn force_chart_window_keeps_landing_pulses_visible() {
    // The handling line: apples land on the belt and ride it for seconds, one contact each. The
    // chart shows the landing pulses (a few ms), not seconds of resting force.
    let mut sc = shipped("scenarios/handling_line.json");
    sc.duration_s = 1.5;
    sc.output.force_history = Some(true.into());
    let root = tmp("plots_window");
    let run = root.join("line");
    applesim::run::to_dir(&sc, &repo("scenarios"), &run, &mut |_| {}).unwrap();
    let s = plot::plot_runs(std::slice::from_ref(&run), &run, &PlotOptions::default()).unwrap();
    println!("{:?}", s.notes);
    let window = force_window_end(&s.notes);
    assert!(window < 50.0, "window {window} ms");
    // Whole impacts are not cut: the elastic drop of Fig. 1 is drawn to its end.
    let curve: Vec<(f64, f64)> = (0..=100)
        .map(|i| {
            let t = 5.6 * i as f64 / 100.0;
            (t, (std::f64::consts::PI * t / 5.6).sin().powf(1.5))
        })
        .collect();
    assert_eq!(plot::force_window_ms(&[&curve]), 5.6);
}

/// The end of the force chart's window (ms) from its note ("force chart: 0 to 12.3 ms since
/// first touch (...)").
fn force_window_end(notes: &[String]) -> f64 {
    let note = notes
        .iter()
        .find(|n| n.starts_with("force chart: "))
        .unwrap_or_else(|| panic!("no force chart window note in {notes:?}"));
    let rest = &note[note.find(" to ").expect("FROM to TO") + 4..];
    rest.split(' ').next().unwrap().parse().unwrap()
}

#[test]
fn force_chart_default_window_is_around_the_impact_of_a_resting_apple() {
    // Issue 20: an apple dropped on the plate (ke = 0.09) lands, bounces once a millimetre and
    // rests on it for the rest of the 0.5 s run: a contact of about 470 ms whose impact is over
    // in a few ms. The default window spans the impact pulses and a fifth more (the landing's
    // pulse lasts until it parts, 22 ms after the touch, the force slowly fading), not the
    // whole contact; --window overrides it.
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.duration_s = 0.5;
    sc.contact.ke = Some(0.09);
    sc.apples[0].velocity_m_s = [0.0, 0.0, -0.5];
    // The whole contact's force: the chart's window, not the history kept, cuts the rest.
    sc.output.force_history = Some(applesim::scenario::ForceHistory::Full);
    let root = tmp("plots_resting");
    let run = root.join("rest");
    applesim::run::to_dir(&sc, &repo("scenarios"), &run, &mut |_| {}).unwrap();
    let contacts = std::fs::read_to_string(run.join("contacts.csv")).unwrap();
    let mut rows = csv::Reader::from_reader(contacts.as_bytes());
    let h = rows.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|c| c == n).unwrap();
    let recs: Vec<csv::StringRecord> = rows.records().map(|r| r.unwrap()).collect();
    let num = |r: &csv::StringRecord, n: &str| r[col(n)].parse::<f64>().ok();
    // The longest impact pulse of the landing and the bounces (the contact that starts at the
    // last bounce and rests to the end of the run has one too, over before it rests).
    let impact_ms = 1e3
        * recs
            .iter()
            .filter_map(|r| num(r, "impact_duration_s"))
            .fold(0.0, f64::max);
    let last = recs.last().unwrap();
    assert!(last[col("t_end_s")].is_empty(), "still resting at the end");
    let start_ms = 1e3 * num(last, "t_start_s").unwrap();
    assert!(start_ms < 100.0, "resting from {start_ms} ms");
    let s = plot::plot_runs(std::slice::from_ref(&run), &run, &PlotOptions::default()).unwrap();
    let window = force_window_end(&s.notes);
    println!(
        "{} contacts, longest impact {impact_ms:.3} ms, resting contact {:.1} ms, default window to {window} ms",
        recs.len(),
        500.0 - start_ms
    );
    assert!(
        window >= impact_ms,
        "window to {window} ms, impact {impact_ms} ms"
    );
    assert!(
        window <= (1.0 + plot::IMPACT_WINDOW_MARGIN) * impact_ms + 0.1,
        "window to {window} ms, impact {impact_ms} ms"
    );
    assert!(
        window < 0.1 * (500.0 - start_ms),
        "window {window} ms of a {} ms contact",
        500.0 - start_ms
    );
    read_svg(&run.join("force_time.svg"));

    // --window FROM:TO replaces it.
    let opts = PlotOptions {
        force_window_ms: Some(plot::ChartWindow::parse("--window", "1:100", "ms").unwrap()),
        ..PlotOptions::default()
    };
    let s = plot::plot_runs(std::slice::from_ref(&run), &run, &opts).unwrap();
    assert_eq!(force_window_end(&s.notes), 100.0, "{:?}", s.notes);
    assert!(
        s.notes
            .iter()
            .any(|n| n.contains("force chart: 1 to 100 ms")),
        "{:?}",
        s.notes
    );
    // Bad windows are refused with the option named.
    for bad in ["5", "5:1", "a:2", "-1:3"] {
        let e = plot::ChartWindow::parse("--window", bad, "ms")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(&format!("--window {bad}: ")), "{e}");
    }
}

#[test]
fn time_window_of_the_charts_against_time() {
    // Issue 20: `--time-window FROM:TO` (s) restricts the slip, speed and spin charts, in
    // `applesim run --plots` and in `applesim plot`. Figs. 6-7's apple starts rolling at
    // 48.5 ms: a window from 60 to 100 ms leaves the transition mark out and starts its time
    // axis at 0.06 s.
    let bin = env!("CARGO_BIN_EXE_applesim");
    let dir = tmp("plots_time_window");
    let st = std::process::Command::new(bin)
        .arg("run")
        .arg(repo("scenarios/slip_to_roll.json"))
        .arg("--out")
        .arg(dir.join("run"))
        .args(["--plots", "--quiet", "--time-window", "0.06:0.1"])
        .status()
        .unwrap();
    assert!(st.success());
    let whole = tmp("plots_time_window_whole");
    let st = std::process::Command::new(bin)
        .arg("plot")
        .arg(dir.join("run"))
        .arg("--out")
        .arg(&whole)
        .status()
        .unwrap();
    assert!(st.success());
    let windowed = dir.join("plotted");
    let st = std::process::Command::new(bin)
        .arg("plot")
        .arg(dir.join("run"))
        .arg("--out")
        .arg(&windowed)
        .args(["--time-window", "0.06:0.1"])
        .status()
        .unwrap();
    assert!(st.success());
    for (d, cut) in [(dir.join("run"), true), (windowed, true), (whole, false)] {
        for f in [plot::SLIP_CHART, plot::SPEED_CHART] {
            let svg = read_svg(&d.join(f));
            let has = |t: &str| svg.texts.iter().any(|x| x == t);
            // The x axis: ticks every 5 ms inside the window, every 20 ms over the whole run.
            assert_eq!(has("0.065"), cut, "{}/{f}: {:?}", d.display(), svg.texts);
            assert_eq!(has("0.14"), !cut, "{}/{f}: {:?}", d.display(), svg.texts);
            if f == plot::SLIP_CHART {
                assert_eq!(
                    has("to rolling"),
                    !cut,
                    "{}/{f}: {:?}",
                    d.display(),
                    svg.texts
                );
            }
        }
    }
    // A bad window is refused before anything runs, naming the option.
    let out = std::process::Command::new(bin)
        .arg("run")
        .arg(repo("scenarios/slip_to_roll.json"))
        .arg("--out")
        .arg(dir.join("bad"))
        .args(["--plots", "--time-window", "0.1:0.05"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.starts_with("error: --time-window 0.1:0.05: "), "{err}");
    assert!(!dir.join("bad").exists());
}
