//! Outputs sized for batches (issue 31 item 1): every reader of the project reads a run folder
//! written with `output.compress` (every CSV as NAME.csv.gz) as it reads the plain one; the
//! default impact force histories leave the pulse fits and the force chart of impacts as the
//! whole-contact histories had them; the default sample interval and the size estimate are as
//! documented.

use applesim::output::csv_file;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("applesim-gz-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The handling line with its instrumented sphere (transfer points, a probe, transitions),
/// shortened to 3 s, force histories kept, ParaView frames, in the form asked.
fn line(compress: bool) -> applesim::scenario::Scenario {
    let mut v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(repo("scenarios/handling_line_probe.json")).unwrap())
            .unwrap();
    v["duration_s"] = serde_json::json!(3.0);
    v["output"]["force_history"] = serde_json::json!(true);
    v["output"]["compress"] = serde_json::json!(compress);
    v["output"]["vtk"] = serde_json::json!({"interval_s": 0.5});
    let mut sc = applesim::scenario::from_json(&v.to_string(), "line").unwrap();
    sc.read_files(&repo("scenarios")).unwrap();
    applesim::scenario::validate(&sc).unwrap();
    sc
}

fn run_into(sc: &applesim::scenario::Scenario, dir: &Path) {
    applesim::run::to_dir(sc, &repo("scenarios"), dir, &mut |_| {}).unwrap();
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// One run written plain and gzipped: the gzipped folder holds the same files with `.gz` on
/// every CSV; the chart reader (`applesim plot`), the line report (`applesim report`), the audit
/// reader (`applesim audit`, here through the command), the viewer (`applesim view`) and the
/// ParaView writer (which reads bodies.csv back) give the same results from both.
#[test]
fn every_reader_reads_both_forms() {
    let base = scratch("readers");
    let (plain, gz) = (base.join("plain"), base.join("gz"));
    run_into(&line(false), &plain);
    run_into(&line(true), &gz);
    let p = names(&plain);
    let g: Vec<String> = names(&gz)
        .into_iter()
        .filter(|n| n != applesim::output::CONTACTS_JSON_GZ)
        .map(|n| n.strip_suffix(".gz").map(String::from).unwrap_or(n))
        .collect();
    assert_eq!(p, g, "the same files, every CSV gzipped");
    // summary.json's contact list, gzipped beside it: the same objects.
    let summary = |d: &Path| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(d.join("summary.json")).unwrap()).unwrap()
    };
    let (_, list) = csv_file::open(&gz.join(applesim::output::CONTACTS_JSON_GZ)).unwrap();
    let list: serde_json::Value = serde_json::from_reader(list).unwrap();
    assert!(summary(&gz).get("contacts").is_none());
    assert_eq!(summary(&gz)["contacts_file"], "contacts.json.gz");
    assert_eq!(summary(&plain)["contacts"], list);
    for n in names(&gz) {
        assert!(!n.ends_with(".csv"), "{n} is not gzipped");
    }
    assert!(p.iter().any(|n| n.starts_with("probe_")), "{p:?}");
    assert!(p.contains(&"forces.csv".to_string()), "{p:?}");
    assert!(p.contains(&"transitions.csv".to_string()), "{p:?}");
    // Every CSV reads back as the same text, through the one opener.
    for n in p.iter().filter(|n| n.ends_with(".csv")) {
        let read = |dir: &Path| {
            let (_, mut r) = csv_file::open(&dir.join(n)).unwrap();
            let mut s = String::new();
            std::io::Read::read_to_string(&mut r, &mut s).unwrap();
            s
        };
        assert!(read(&plain) == read(&gz), "{n}");
    }
    // The ParaView frames were written from bodies.csv.gz as from bodies.csv.
    for f in names(&plain.join("vtk")) {
        assert!(
            std::fs::read(plain.join("vtk").join(&f)).unwrap()
                == std::fs::read(gz.join("vtk").join(&f)).unwrap(),
            "vtk/{f}"
        );
    }
    // Charts.
    let (a, b) = (
        applesim::output::plot::read_run(&plain).unwrap(),
        applesim::output::plot::read_run(&gz).unwrap(),
    );
    assert!(!a.forces.is_empty() && !a.apples.is_empty() && !a.transitions.is_empty());
    // (Debug text: a NaN `along_m` is not equal to itself.)
    assert!(
        format!("{a:?}") == format!("{b:?}"),
        "plot::read_run differs"
    );
    // Report.
    let (a, b) = (
        applesim::output::report::line_report(&plain, "cmd").unwrap(),
        applesim::output::report::line_report(&gz, "cmd").unwrap(),
    );
    assert!(a == b, "report differs");
    // Audit, as a library call and as the command.
    let (a, b) = (
        applesim::output::audit::read_audit(&csv_file::locate(&plain, "audit.csv")).unwrap(),
        applesim::output::audit::read_audit(&csv_file::locate(&gz, "audit.csv")).unwrap(),
    );
    assert!(!a.points.is_empty());
    assert_eq!(a, b, "read_audit");
    let out = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .arg("audit")
        .arg(&plain)
        .arg(&gz)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Viewer.
    let opts = applesim::view::ViewOptions {
        max_frames: 50,
        asset_dir: Some(repo("scenarios")),
        label: Some("run".into()),
    };
    let (pa, pb) = (base.join("plain.html"), base.join("gz.html"));
    let sa = applesim::view::write_view(&plain, &pa, &opts).unwrap();
    let sb = applesim::view::write_view(&gz, &pb, &opts).unwrap();
    assert_eq!(sa, sb, "view stats");
    assert!(
        std::fs::read(&pa).unwrap() == std::fs::read(&pb).unwrap(),
        "view.html"
    );
    let _ = std::fs::remove_dir_all(&base);
}

/// A batch of gzipped runs: `applesim merge` tabulates it as a plain one, and the validation's
/// reader of a batch's run folders (contacts.csv, bodies.csv) reads them.
#[test]
fn merge_and_the_batch_reader_read_gzipped_runs() {
    let base = scratch("batch");
    let spec = base.join("spec.json");
    let mut out = Vec::new();
    for compress in [false, true] {
        let spec_json = serde_json::json!({
            "base": repo("scenarios/drop_on_steel.json"),
            "set": { "/output/compress": compress },
            "parameters": [ { "name": "vz_m_s", "path": "/apples/0/velocity_m_s/2",
                              "values": [-0.5, -1.0] } ]
        });
        std::fs::write(&spec, serde_json::to_vec_pretty(&spec_json).unwrap()).unwrap();
        let dir = base.join(if compress { "gz" } else { "plain" });
        let ex = applesim::validate::runs::execute(&spec, &dir, 1).unwrap();
        assert_eq!(ex.runs.len(), 2);
        let mut seen = Vec::new();
        for r in &ex.runs {
            assert!(csv_file::locate(&r.dir, "bodies.csv")
                .display()
                .to_string()
                .ends_with(if compress { ".csv.gz" } else { ".csv" }));
            let bodies = r.bodies("a1").unwrap();
            assert!(!bodies.is_empty() && !r.contacts.is_empty());
            let curve = r.force_curve(r.contacts[0].index).unwrap();
            seen.push((r.contacts.clone(), bodies, curve.points));
        }
        // merged.csv: both runs ok, with their metrics (the ids differ: they hash the scenario).
        let merged = std::fs::read_to_string(dir.join("merged.csv")).unwrap();
        assert_eq!(merged.lines().count(), 3, "{merged}");
        for row in merged.lines().skip(1) {
            assert!(row.contains(",ok,"), "{merged}");
        }
        out.push(seen);
    }
    assert_eq!(
        out[0], out[1],
        "the same figures from plain and gzipped runs"
    );
    let _ = std::fs::remove_dir_all(&base);
}

/// The default impact histories keep what the pulse fits and the force chart use: on a drop that
/// bounces and then rests on the floor, pulse_fits.csv and force_time.svg are the same bytes as
/// with whole-contact histories (`"full"`), while forces.csv holds the resting contact's impact
/// and as much again, not its rest (contacts.csv `force_history_cut_s`). (The resting contact
/// lasts under 4096 steps here: a longer one's whole history is thinned evenly to 4096 samples,
/// and its impact then drawn coarser than the impact history draws it.)
#[test]
fn impact_histories_leave_the_fits_and_the_chart_of_impacts_unchanged() {
    let base = scratch("histories");
    // Both runs into the same folder, so that the charts name the same run.
    let dir = base.join("run");
    let mut files = Vec::new();
    for history in ["full", "impact"] {
        let v = serde_json::json!({
            "duration_s": 0.3, "time_step_s": 5e-5, "gravity_m_s2": [0, 0, -9.81],
            "output": { "sample_interval_s": 0.01, "force_history": history },
            "materials": { "apple": { "preset": "apple-paper" }, "steel": { "preset": "steel-paper" } },
            "contact": { "friction": 0.5, "ke": 0.3, "lambda_s_m": 100 },
            "apples": [ { "name": "a1", "material": "apple", "diameter_m": 0.08,
                          "position_m": [0, 0, 0.06] } ],
            "surfaces": [ { "name": "floor", "type": "plane", "material": "steel",
                            "point_m": [0, 0, 0], "normal": [0, 0, 1] } ]
        });
        let sc = applesim::scenario::from_json(&v.to_string(), "drop").unwrap();
        applesim::scenario::validate(&sc).unwrap();
        run_into(&sc, &dir);
        let charts = base.join("charts");
        let _ = std::fs::remove_dir_all(&charts);
        std::fs::create_dir_all(&charts).unwrap();
        applesim::output::plot::plot_runs(
            std::slice::from_ref(&dir),
            &charts,
            &applesim::output::plot::PlotOptions::default(),
        )
        .unwrap();
        let read = |p: PathBuf| std::fs::read_to_string(p).unwrap();
        files.push([
            read(dir.join("pulse_fits.csv")),
            read(charts.join("force_time.svg")),
            read(dir.join("forces.csv")),
            read(dir.join("contacts.csv")),
        ]);
    }
    let (full, impact) = (&files[0], &files[1]);
    assert!(
        full[0].lines().count() >= 3,
        "two bounces fitted:\n{}",
        full[0]
    );
    assert_eq!(full[0], impact[0], "pulse_fits.csv");
    assert!(full[1] == impact[1], "force_time.svg differs");
    let rows = |s: &str| s.lines().count();
    assert!(
        rows(&impact[2]) < rows(&full[2]),
        "forces.csv: {} rows against {}",
        rows(&impact[2]),
        rows(&full[2])
    );
    let mut rd = csv::Reader::from_reader(impact[3].as_bytes());
    let col = rd
        .headers()
        .unwrap()
        .iter()
        .position(|h| h == "force_history_cut_s")
        .unwrap();
    let cuts: Vec<String> = rd.records().map(|r| r.unwrap()[col].to_string()).collect();
    assert_eq!(cuts.iter().filter(|c| !c.is_empty()).count(), 1, "{cuts:?}");
    let _ = std::fs::remove_dir_all(&base);
}
