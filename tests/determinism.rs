//! The same scenario gives byte-identical outputs (README "Outputs": "The same scenario gives
//! byte-identical files; only `wall_time_s` is a measurement"): every file a run writes, found by
//! listing the run folders (sub-folders included), not a fixed list; in summary.json every field
//! but `wall_time_s`. The runs cover every kind of file: summary.json, contacts.csv, bodies.csv,
//! transitions.csv, apple_contacts.csv, bruises.csv, audit.csv, forces.csv, pulse_fits.csv, scenario.json, the charts of
//! `--plots` and the ParaView series (scene.pvd, vtk/).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

fn run_cli(scenario: &Path, out: &Path, extra: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .arg("run")
        .arg(scenario)
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn without_wall_time(p: &Path) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap();
    v.as_object_mut().unwrap().remove("wall_time_s");
    v
}

/// Every file under `dir`, as paths relative to it.
fn files(dir: &Path) -> BTreeSet<PathBuf> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeSet<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                out.insert(p.strip_prefix(root).unwrap().to_path_buf());
            }
        }
    }
    let mut out = BTreeSet::new();
    walk(dir, dir, &mut out);
    out
}

/// The two run folders hold the same files with the same bytes (summary.json but its wall time).
/// Returns the file names.
fn assert_same_files(what: &str, a: &Path, b: &Path) -> BTreeSet<PathBuf> {
    let (fa, fb) = (files(a), files(b));
    assert_eq!(fa, fb, "{what}: the two runs wrote different files");
    for f in &fa {
        if f == Path::new("summary.json") {
            assert_eq!(
                without_wall_time(&a.join(f)),
                without_wall_time(&b.join(f)),
                "{what}: summary.json differs"
            );
        } else {
            let (x, y) = (
                std::fs::read(a.join(f)).unwrap(),
                std::fs::read(b.join(f)).unwrap(),
            );
            assert!(!x.is_empty(), "{what}: {} is empty", f.display());
            assert!(x == y, "{what}: {} differs between two runs", f.display());
        }
    }
    fa
}

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

#[test]
fn two_runs_write_identical_files() {
    let base = std::env::temp_dir().join(format!("applesim-det-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&base);
    std::fs::create_dir_all(&base).unwrap();
    // The drop with a ParaView series, so that every kind of file is written.
    let mut drop: serde_json::Value =
        serde_json::from_slice(&std::fs::read(repo("scenarios/drop_on_steel.json")).unwrap())
            .unwrap();
    drop["output"]["vtk"] = serde_json::json!({ "interval_s": 0.005 });
    let drop_vtk = base.join("drop_vtk.json");
    std::fs::write(&drop_vtk, serde_json::to_vec_pretty(&drop).unwrap()).unwrap();
    let mut seen = BTreeSet::new();
    for sc in [
        repo("scenarios/slip_to_roll.json"),
        repo("scenarios/two_apples_head_on.json"),
        repo("scenarios/handling_line.json"),
        drop_vtk,
    ] {
        let name = sc.file_stem().unwrap().to_string_lossy().to_string();
        let (a, b) = (
            base.join(format!("{name}-a")),
            base.join(format!("{name}-b")),
        );
        run_cli(&sc, &a, &["--plots"]);
        run_cli(&sc, &b, &["--plots"]);
        let f = assert_same_files(&name, &a, &b);
        println!("{name}: {} files identical", f.len());
        seen.extend(f.into_iter().map(|p| {
            // vtk/apples_000001.vtp -> vtk/apples_*.vtp
            let s = p.to_string_lossy().to_string();
            if s.starts_with("vtk/apples_") {
                "vtk/apples_*.vtp".to_string()
            } else {
                s
            }
        }));
    }
    // Every kind of output file was compared.
    for f in [
        "summary.json",
        "contacts.csv",
        "bodies.csv",
        "transitions.csv",
        "apple_contacts.csv",
        "bruises.csv",
        "audit.csv",
        "forces.csv",
        "pulse_fits.csv",
        "scenario.json",
        "force_time.svg",
        "linear_velocity.svg",
        "angular_velocity.svg",
        "slip_speed.svg",
        "rolling_starts.svg",
        "scene.pvd",
        "vtk/surfaces.vtp",
        "vtk/apples_*.vtp",
    ] {
        assert!(seen.contains(f), "no run wrote {f}: {seen:?}");
    }
    let _ = std::fs::remove_dir_all(&base);
}

/// The force pass runs in parallel once a step has enough contacts (a pile); its sums are taken
/// in a fixed order, so one thread and two give the same bytes, in every file.
/// 288 apples dropped into a steel bin (a 6 x 6 x 8 grid, 0.25 s at dt 1e-4 s): about 600
/// contacts per step at the end, above the parallel force pass's threshold.
fn grid_pile() -> serde_json::Value {
    serde_json::json!({
        "description": "pile for the thread-count determinism test",
        "duration_s": 0.25,
        "time_step_s": 1e-4,
        "gravity_m_s2": [0, 0, -9.81],
        "output": { "sample_interval_s": 0.05 },
        "materials": {
            "apple": { "youngs_modulus_pa": 2.6e6, "poisson_ratio": 0.18, "density_kg_m3": 800 },
            "steel": { "youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.3 }
        },
        "contact": { "friction": 0.5, "ke": 0.3, "lambda_s_m": 1000 },
        "generators": [ { "type": "grid", "name": "a", "material": "apple",
            "diameter_m": { "mean_m": 0.08, "spread_m": 0.008 },
            "count": [6, 6, 8], "spacing_m": [0.095, 0.095, 0.095],
            "origin_m": [-0.2375, -0.2375, 0.05], "jitter_m": 0.004, "seed": 3 } ],
        "surfaces": [ { "name": "bin", "type": "bin", "material": "steel",
            "inner_size_m": [0.6, 0.6, 0.5], "position_m": [0, 0, 0] } ]
    })
}

#[test]
fn one_thread_and_two_write_identical_files() {
    let base = std::env::temp_dir().join(format!("applesim-threads-{}", std::process::id()));
    std::fs::create_dir_all(&base).unwrap();
    // 288 apples dropped into a bin: about 600 contacts per step at the end, above the
    // parallel threshold.
    let sc = grid_pile();
    let path = base.join("pile.json");
    std::fs::write(&path, serde_json::to_vec_pretty(&sc).unwrap()).unwrap();
    let (a, f) = one_thread_and_two(&path, &base, "t", "--threads 1 and 2");
    let contacts = std::fs::read_to_string(a.join("contacts.csv")).unwrap();
    assert!(
        contacts.lines().count() > 300,
        "the pile should produce many contacts"
    );
    assert!(f.len() >= 6, "{f:?}");
    // Gzipped (output.compress): the same bytes at one thread and two, every CSV as NAME.csv.gz,
    // holding the plain run's text, and summary.json's contact list in contacts.json.gz.
    let mut gz = sc.clone();
    gz["output"]["compress"] = serde_json::json!(true);
    let gz_path = base.join("pile_gz.json");
    std::fs::write(&gz_path, serde_json::to_vec_pretty(&gz).unwrap()).unwrap();
    let (c, g) = one_thread_and_two(&gz_path, &base, "gz", "gzipped, --threads 1 and 2");
    let plain_csv: BTreeSet<String> = f
        .iter()
        .map(|p| p.display().to_string())
        .filter(|n| n.ends_with(".csv"))
        .collect();
    let gz_csv: BTreeSet<String> = g
        .iter()
        .map(|p| p.display().to_string())
        .filter_map(|n| n.strip_suffix(".csv.gz").map(|n| format!("{n}.csv")))
        .collect();
    assert!(g.contains(Path::new(applesim::output::CONTACTS_JSON_GZ)));
    assert_eq!(gz_csv, plain_csv, "every CSV gzipped, and only they");
    assert!(!g.iter().any(|p| p.display().to_string().ends_with(".csv")));
    for name in &plain_csv {
        let mut text = String::new();
        let (_, mut r) = applesim::output::csv_file::open(&c.join(name)).unwrap();
        std::io::Read::read_to_string(&mut r, &mut text).unwrap();
        assert!(
            text == std::fs::read_to_string(a.join(name)).unwrap(),
            "{name}: the gzipped file does not hold the plain one's text"
        );
    }
    let _ = std::fs::remove_dir_all(&base);
}

/// Issue 31: a moving source (the fill head of scenarios/lines/bin_filler_head.json, lowered
/// with its bin, apples waiting for their spot and entering where the head is then) writes the
/// same bytes with one thread and two, in every file (summary.json's `apples[].fed` included).
#[test]
fn a_moving_source_writes_the_same_bytes_with_one_thread_and_two() {
    same_bytes_with_one_thread_and_two("scenarios/lines/bin_filler_head.json", "head");
}

/// Issue 30: apples riding a belt (the handling line: its 20 apples ride the belt until its end,
/// and are woken there) write the same bytes with one thread and two.
#[test]
fn riders_write_the_same_bytes_with_one_thread_and_two() {
    same_bytes_with_one_thread_and_two("scenarios/handling_line.json", "riders");
}

/// Runs a shipped scenario with `--threads 1` and `--threads 2` and compares every file.
fn same_bytes_with_one_thread_and_two(scenario: &str, tag: &str) {
    let base = std::env::temp_dir().join(format!("applesim-{tag}-{}", std::process::id()));
    let what = format!("{scenario}, --threads 1 and 2");
    let (_, f) = one_thread_and_two(&repo(scenario), &base, "t", &what);
    assert!(f.len() >= 6, "{f:?}");
    let _ = std::fs::remove_dir_all(&base);
}

/// Runs `scenario` into `base/{tag}1` with one thread and `base/{tag}2` with two, checks that
/// they hold the same files with the same bytes, and returns the first folder and the files.
fn one_thread_and_two(
    scenario: &Path,
    base: &Path,
    tag: &str,
    what: &str,
) -> (PathBuf, BTreeSet<PathBuf>) {
    let (a, b) = (base.join(format!("{tag}1")), base.join(format!("{tag}2")));
    run_cli(scenario, &a, &["--threads", "1"]);
    run_cli(scenario, &b, &["--threads", "2"]);
    let f = assert_same_files(what, &a, &b);
    (a, f)
}

/// Issue 29: spheroids (the 288-apple grid of `one_thread_and_two_write_identical_files` with
/// aspect 0.85 +- 0.05, turned at random: 365 contacts per step at the end (1.267 per apple,
/// `applesim bench --window 0.2:0.25`), above the 256 of the
/// parallel force pass) write the same bytes with one thread and two, the shape columns of
/// bodies.csv included.
#[test]
fn spheroids_write_the_same_bytes_with_one_thread_and_two() {
    let base = std::env::temp_dir().join(format!("applesim-spheroids-{}", std::process::id()));
    std::fs::create_dir_all(&base).unwrap();
    let mut sc = grid_pile();
    sc["generators"][0]["aspect"] = serde_json::json!({ "mean": 0.85, "spread": 0.05 });
    let path = base.join("pile.json");
    std::fs::write(&path, serde_json::to_vec_pretty(&sc).unwrap()).unwrap();
    let (a, f) = one_thread_and_two(&path, &base, "t", "spheroids, --threads 1 and 2");
    let bodies = std::fs::read_to_string(a.join("bodies.csv")).unwrap();
    assert!(
        bodies
            .lines()
            .next()
            .unwrap()
            .ends_with("height_m,qw,qx,qy,qz"),
        "shape columns"
    );
    assert!(f.len() >= 5, "{f:?}");
    let _ = std::fs::remove_dir_all(&base);
}

/// Issue 30 item 2: with more than one thread, a scene of `APPLE_SETS_MIN_APPLES` apples or more
/// spreads them over rapier body sets that are stepped concurrently (`World::split_apples`,
/// `layer::BodySets`). An apple touches nothing in rapier and is integrated on its own, so the
/// split must change no bit: the 288-apple grid pile (0.25 s) stepped with one, two and three
/// sets ends with every apple's position, velocity and spin equal bit for bit, and the same
/// finished contact events.
#[test]
fn apples_split_over_body_sets_move_the_same_bits() {
    let sc: applesim::scenario::Scenario = serde_json::from_value(grid_pile()).unwrap();
    let run = |threads: usize| {
        let (bits, events, text, sets) = run_to_end(&sc, threads);
        assert_eq!(sets, threads, "{threads} threads");
        (bits, events, text)
    };
    let one = run(1);
    assert_eq!(one.0.len(), 288);
    assert!(one.1 > 300, "the pile's contact events: {}", one.1);
    for threads in [2, 3] {
        let split = run(threads);
        assert!(
            split.0 == one.0,
            "{threads} body sets: an apple moved differently"
        );
        assert!(
            split.2 == one.2,
            "{threads} body sets: the contact events differ"
        );
    }
}

/// Riders leave rapier few bodies to step: below `world::APPLE_SETS_PARALLEL_MIN_AWAKE` awake
/// apples the body sets are stepped one after the other, above it concurrently, and neither
/// may change a bit. 324 apples land on a running belt (all awake, the sets concurrent), then
/// ride it (few awake, the sets in turn); one thread and two end with the same bits, and the
/// two-thread run went through both regimes.
#[test]
fn body_sets_stepped_in_turn_or_together_move_the_same_bits() {
    use applesim::record::series::NoSamples;
    use applesim::sim::Simulation;
    use applesim::world::APPLE_SETS_PARALLEL_MIN_AWAKE;
    // The determinism pile's materials and law, on a running belt.
    let mut belt = grid_pile();
    belt["duration_s"] = serde_json::json!(0.9);
    belt["time_step_s"] = serde_json::json!("adaptive");
    belt["materials"]["rubber"] =
        serde_json::json!({ "youngs_modulus_pa": 5e6, "poisson_ratio": 0.45 });
    let g = &mut belt["generators"][0];
    g["diameter_m"]["mean_m"] = serde_json::json!(0.075);
    g["diameter_m"]["spread_m"] = serde_json::json!(0.004);
    g["count"] = serde_json::json!([18, 18, 1]);
    g["spacing_m"] = serde_json::json!([0.1, 0.1, 0.1]);
    g["origin_m"] = serde_json::json!([-0.85, -0.85, 0.0405]);
    g["jitter_m"] = serde_json::json!(0.0);
    g["velocity_m_s"] = serde_json::json!([0.4, 0, 0]);
    belt["surfaces"] = serde_json::json!([{ "name": "belt", "type": "conveyor", "material": "rubber",
        "size_m": [4.0, 2.0, 0.04], "position_m": [0.5, 0, -0.02], "belt_velocity_m_s": 0.4 }]);
    let sc: applesim::scenario::Scenario = serde_json::from_value(belt).unwrap();
    let run = |threads: usize| {
        on_threads(threads, || {
            let mut sim = Simulation::new(&sc, Path::new(".")).unwrap();
            assert_eq!(sim.world().body_set_count(), threads, "{threads} threads");
            let (mut many, mut few) = (0, 0);
            while !sim.done() {
                sim.step(&mut NoSamples).unwrap();
                if sim.world().layer.awake_count() >= APPLE_SETS_PARALLEL_MIN_AWAKE {
                    many += 1;
                } else {
                    few += 1;
                }
            }
            let bits = apple_bits(&mut sim);
            let riding = sim.world().layer.riding_count();
            (bits, many, few, riding)
        })
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one.0.len(), 324);
    assert!(
        two.1 > 0 && two.2 > 0,
        "both regimes: {} steps with many awake, {} with few",
        two.1,
        two.2
    );
    assert!(two.3 > 300, "the apples ride at the end: {}", two.3);
    assert!(two.0 == one.0, "two body sets: an apple moved differently");
}

/// The surface candidates (which apples are near which walls) are listed on rayon's pool from
/// `layer::PARALLEL_MIN_CANDIDATE_APPLES` apples, in runs joined in apple order: 512 apples
/// dropped into a steel bin (an 8 x 8 x 8 grid, 0.1 s, adaptive steps) end with the same bits
/// and the same contact events on one thread and two.
#[test]
fn surface_candidates_listed_in_runs_move_the_same_bits() {
    use applesim::layer::PARALLEL_MIN_CANDIDATE_APPLES;
    let mut bin = grid_pile();
    bin["duration_s"] = serde_json::json!(0.1);
    bin["time_step_s"] = serde_json::json!("adaptive");
    let g = &mut bin["generators"][0];
    g["count"] = serde_json::json!([8, 8, 8]);
    g["origin_m"] = serde_json::json!([-0.3325, -0.3325, 0.05]);
    bin["surfaces"][0]["inner_size_m"] = serde_json::json!([0.8, 0.8, 0.9]);
    let sc: applesim::scenario::Scenario = serde_json::from_value(bin).unwrap();
    let run = |threads: usize| run_to_end(&sc, threads);
    let one = run(1);
    assert!(
        one.0.len() >= PARALLEL_MIN_CANDIDATE_APPLES,
        "{}",
        one.0.len()
    );
    assert!(one.1 > 100, "the bin's contact events: {}", one.1);
    let two = run(2);
    assert!(two.0 == one.0, "two threads: an apple moved differently");
    assert!(two.2 == one.2, "two threads: the contact events differ");
}

/// `sc` run to its end on a pool of `threads`: every apple's bits, the number of finished
/// contact events and their text, and how many rapier body sets the apples were spread over.
fn run_to_end(
    sc: &applesim::scenario::Scenario,
    threads: usize,
) -> (Vec<[u64; 9]>, usize, String, usize) {
    use applesim::record::series::NoSamples;
    on_threads(threads, || {
        let mut sim = applesim::sim::Simulation::new(sc, Path::new(".")).unwrap();
        let sets = sim.world().body_set_count();
        while !sim.done() {
            sim.step(&mut NoSamples).unwrap();
        }
        let bits = apple_bits(&mut sim);
        let events = sim.run(&mut NoSamples, &mut |_| {}).unwrap().events;
        (bits, events.len(), format!("{events:?}"), sets)
    })
}

/// Every apple's position, velocity and spin, as bits.
fn apple_bits(sim: &mut applesim::sim::Simulation) -> Vec<[u64; 9]> {
    sim.apple_states()
        .iter()
        .map(|a| {
            let (p, v, w) = (a.position, a.velocity, a.angular_velocity);
            [p.x, p.y, p.z, v.x, v.y, v.z, w.x, w.y, w.z].map(f64::to_bits)
        })
        .collect()
}

/// `f` run in a pool of `threads` threads.
fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}
