//! Issue 20's acceptance: impacts apart from resting loads, the line audit per transfer point
//! and the virtual instrumented sphere, read from the files a user reads (contacts.csv,
//! audit.csv, probe_NAME_impacts.csv). Closed forms and tolerances: docs/analysis.md, "Impacts,
//! transfer points and the instrumented sphere".

use crate::common;
use applesim::analysis::impacts::STANDARD_GRAVITY;
use applesim::record::probe::ProbeSpec;
use applesim::scenario::{AppleSpec, Scenario};
use common::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("line_audit")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Runs `sc` into a fresh folder the way `applesim run` does.
fn run_folder(sc: &Scenario, name: &str) -> PathBuf {
    applesim::scenario::validate(sc).unwrap_or_else(|e| panic!("{name}: {e}"));
    let out = scratch(name);
    applesim::run::to_dir(sc, &repo("scenarios"), &out, &mut |_| {})
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    out
}

fn rows(path: &Path) -> Vec<BTreeMap<String, String>> {
    let mut rd = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    let header = rd.headers().unwrap().clone();
    rd.records()
        .map(|r| {
            let r = r.unwrap();
            header
                .iter()
                .zip(r.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

fn num(row: &BTreeMap<String, String>, col: &str) -> f64 {
    row[col]
        .parse()
        .unwrap_or_else(|_| panic!("{col} = '{}' in {row:?}", row[col]))
}

/// The Fig. 1 apple on steel without gravity, ke = 0.09, lambda = 1000 s/m: at lambda v0 = 1400
/// eq. 12 rebounds with e = sqrt(ke) = 0.3 (physics.md section 3; measured agreement 0.006 %,
/// docs/claims.md), so the velocity change is (1 + sqrt(ke)) v0; the peak force is Hertz's
/// P_max (unchanged by the hysteresis in that limit) and the peak g is P_max / (m g).
#[test]
fn a_drop_reports_one_plus_e_v0_and_peak_g_of_the_peak_force() {
    let v0 = 1.4;
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.gravity_m_s2 = [0.0; 3];
    sc.contact.ke = Some(0.09);
    sc.apples[0].velocity_m_s = [0.0, 0.0, -v0];
    let out = run_folder(&sc, "drop");
    let c = rows(&out.join("contacts.csv"));
    assert_eq!(c.len(), 1, "one contact");
    let c = &c[0];
    let m = 0.107;
    assert_eq!(num(c, "a_mass_kg"), m);
    assert_eq!(num(c, "a_diameter_m"), 0.08);
    let dv = num(c, "a_velocity_change_m_s");
    // docs/analysis.md: 1.82001 against (1 + 0.3) 1.4 = 1.82 m/s, +0.0003 %: checked with its
    // sign at twice that.
    let off = dv / ((1.0 + 0.09f64.sqrt()) * v0) - 1.0;
    println!("velocity change {dv} m/s: {:+.5} %", 100.0 * off);
    assert!(off > 0.0 && off <= 2.0 * 0.0003e-2, "{off}");
    let (_, p_max, _, _) = ode::elastic_closed_form(m, v0, ode::fig1_k(), 0.04);
    let peak = num(c, "impact_peak_force_n");
    // -0.004 % from Hertz's P_max (the eq. 12 peak at lambda v0 = 1400, a touch under it):
    // with its sign at twice that.
    let off = peak / p_max - 1.0;
    println!(
        "impact peak {peak} N against P_max {p_max} N: {:+.5} %",
        100.0 * off
    );
    assert!((-2.0 * 0.004e-2..0.0).contains(&off), "{off}");
    assert_ref(
        "peak g",
        num(c, "a_peak_g"),
        p_max / (m * STANDARD_GRAVITY),
        2.0 * 0.004e-2,
        "closed form",
    );
    // The reported peak force over the weight, to the 9 printed digits of each (5e-9 each).
    let g = peak / (m * STANDARD_GRAVITY);
    assert!((num(c, "a_peak_g") - g).abs() <= 1e-8 * g);
    // The one rebound is the whole contact: no resting part.
    assert_eq!(c["resting_s"], "", "{c:?}");
    // audit.csv: one transfer point, the floor, with the same figures.
    let a = rows(&out.join("audit.csv"));
    assert_eq!(a.len(), 1);
    assert_eq!(a[0]["transfer_point"], "floor");
    assert_eq!(num(&a[0], "velocity_change_m_s_max"), dv);
    assert_eq!(num(&a[0], "peak_g_max"), num(c, "a_peak_g"));
}

/// The shipped slip_to_roll scenario: the apple is set down at its resting sag and slides at
/// 0.5 m/s. Its one contact never lands: it is resting from the start, with no impact and no
/// velocity change (the issue's 1.47 m/s was the impulse over the mass of the whole slide).
#[test]
fn a_contact_that_starts_at_rest_has_no_impact_velocity_change() {
    let sc = shipped("scenarios/slip_to_roll.json");
    let out = run_folder(&sc, "slip_to_roll");
    let c = rows(&out.join("contacts.csv"));
    assert_eq!(c.len(), 1);
    let c = &c[0];
    for col in [
        "a_velocity_change_m_s",
        "a_peak_g",
        "impact_peak_force_n",
        "impact_duration_s",
    ] {
        assert_eq!(c[col], "", "{col}: {c:?}");
    }
    assert!(num(c, "resting_s") > 0.14, "{c:?}");
    // Resting at (1 + ke)/2 of the weight's Hertz overlap: the mean static force is the weight.
    assert_ref(
        "mean resting force",
        num(c, "resting_mean_force_n"),
        0.107 * 9.81,
        1e-3,
        "weight",
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    // No impact: the run's largest impact velocity change and peak g are zero.
    assert_eq!(summary["metrics"]["max_velocity_change_m_s"], 0.0);
    assert_eq!(summary["metrics"]["max_peak_g"], 0.0);
    assert_eq!(summary["metrics"]["plate.impacts"], 0.0);
    let a = rows(&out.join("audit.csv"));
    assert_eq!(a.len(), 1);
    assert_eq!(a[0]["contacts"], "1");
    assert_eq!(a[0]["impacts"], "0");
}

/// The shipped handling line: every transfer point of contacts.csv is a row of audit.csv, with
/// as many contacts, and as many impacts as contacts.csv rows with an impact there; every
/// velocity change is at most (1 + 1) times the fastest approach in the run (no rebound
/// gains speed).
#[test]
fn every_transfer_point_of_the_handling_line_is_audited() {
    let sc = shipped("scenarios/handling_line.json");
    let out = run_folder(&sc, "handling_line");
    let contacts = rows(&out.join("contacts.csv"));
    let mut want: BTreeMap<String, (usize, usize)> = BTreeMap::new();
    for c in &contacts {
        let e = want.entry(c["transfer_point"].clone()).or_default();
        e.0 += 1;
        e.1 += usize::from(!c["impact_peak_force_n"].is_empty());
    }
    let audit = rows(&out.join("audit.csv"));
    let got: BTreeMap<String, (usize, usize)> = audit
        .iter()
        .map(|r| {
            (
                r["transfer_point"].clone(),
                (
                    r["contacts"].parse().unwrap(),
                    r["impacts"].parse().unwrap(),
                ),
            )
        })
        .collect();
    println!("{got:?}");
    assert_eq!(got, want);
    for p in ["belt", "chute", "bin/floor", "apples in bin"] {
        assert!(got.contains_key(p), "{p} missing: {got:?}");
    }
    let fastest = contacts
        .iter()
        .map(|c| num(c, "approach_speed_m_s"))
        .fold(0.0, f64::max);
    for c in &contacts {
        for col in ["a_velocity_change_m_s", "b_velocity_change_m_s"] {
            if let Ok(dv) = c[col].parse::<f64>() {
                assert!(dv <= 2.0 * fastest, "{col} {dv} > 2 x {fastest}: {c:?}");
            }
        }
    }
    // docs/analysis.md (golden, printed digits): feed-2 hits the bin's wall x_max at 0.23 m/s
    // while feed-3 pushes on it; its velocity change reads 0.23 m/s, where the contact's impulse
    // over its mass would read 1.75 m/s over the impact pulse (3.14 over the whole contact).
    let landing = contacts
        .iter()
        .find(|c| {
            c["a"] == "feed-2"
                && c["b"] == "bin/x_max"
                && (num(c, "approach_speed_m_s") - 0.23).abs() <= 0.005
        })
        .expect("feed-2's hit on the bin wall");
    let m = num(landing, "a_mass_kg");
    // 3.14 m/s is a measured figure of docs/analysis.md, not pi.
    #[allow(clippy::approx_constant)]
    for (what, got, doc) in [
        (
            "velocity change",
            num(landing, "a_velocity_change_m_s"),
            0.23,
        ),
        (
            "impact impulse / m",
            num(landing, "impact_impulse_n_s") / m,
            1.75,
        ),
        ("impulse / m", num(landing, "impulse_n_s") / m, 3.14),
    ] {
        assert!(
            (got - doc).abs() <= 0.01,
            "{what}: {got}, docs/analysis.md {doc}"
        );
    }
    // Most damage first: apples downgraded there, then the bruise volume that arose there.
    let keys: Vec<(f64, f64)> = audit
        .iter()
        .map(|r| {
            (
                num(r, "apples_downgraded"),
                num(r, "bruise_volume_mm3_total"),
            )
        })
        .collect();
    assert!(
        keys.windows(2)
            .all(|w| w[0].0 > w[1].0 || (w[0].0 == w[1].0 && w[0].1 >= w[1].1)),
        "{keys:?}"
    );
}

/// Whether `p` lies inside a bin of inner size `size` whose floor's top centre is `floor`
/// (unrotated): between its walls, from the floor to the walls' top.
fn inside_bin(p: [f64; 3], floor: [f64; 3], size: [f64; 3]) -> bool {
    (p[0] - floor[0]).abs() <= size[0] / 2.0
        && (p[1] - floor[1]).abs() <= size[1] / 2.0
        && p[2] >= floor[2]
        && p[2] <= floor[2] + size[2]
}

/// Issue 26: an apple-apple hit inside the bin is counted at the bin, not at the chute the
/// falling apple came down (the shipped handling line counted 102 of its 183 at "apples on
/// chute"; the 150-apple bin fill 50 of its heap's hits).
#[test]
fn apple_apple_hits_inside_a_bin_belong_to_the_bin() {
    for (file, floor, size) in [
        (
            "scenarios/handling_line.json",
            [1.9997, 0.0, 0.0],
            [0.5, 0.4, 0.35],
        ),
        (
            "scenarios/lines/bin_filling.json",
            [0.0, 0.0, 0.0],
            [1.2, 1.2, 0.5],
        ),
    ] {
        let sc = shipped(file);
        // The scene's bin is where this test puts it.
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(repo(file)).unwrap()).unwrap();
        let bin = v["surfaces"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["type"] == "bin")
            .unwrap();
        let at = |k: &str| -> Vec<f64> {
            bin[k]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        };
        assert_eq!(at("inner_size_m"), size);
        assert_eq!(at("position_m"), floor);
        assert!(bin.get("rotation").is_none() && bin.get("motion").is_none());
        let out = run_folder(&sc, file.rsplit('/').next().unwrap());
        let contacts = rows(&out.join("contacts.csv"));
        let (mut inside, mut elsewhere) = (0, Vec::new());
        for c in contacts.iter().filter(|c| !c["b_mass_kg"].is_empty()) {
            let p: Vec<f64> = c["contact_point_m"]
                .split(' ')
                .map(|x| x.parse().unwrap())
                .collect();
            if inside_bin([p[0], p[1], p[2]], floor, size) {
                inside += 1;
                if c["transfer_point"] != "apples in bin" {
                    elsewhere.push(c["transfer_point"].clone());
                }
            }
        }
        println!(
            "{file}: {inside} apple-apple contacts inside the bin, {} counted elsewhere",
            elsewhere.len()
        );
        assert!(inside > 100, "{file}: {inside}");
        assert!(elsewhere.is_empty(), "{file}: {elsewhere:?}");
    }
}

/// Issue 26: at the default damage model and grading the shipped handling line's verdict is the
/// fruit's damage, not a threshold that flags every apple alike: its apples fall into at least
/// two different grades. (The count downgraded below US Extra Fancy is no longer a check: the pile
/// in the bin is chaotic, and this run downgrades 20 of 20, into US Fancy, US Utility and cull;
/// 18-20 of 20 over slightly perturbed feed speeds.) Its report leads with the damage: how many
/// apples were downgraded, the part where most bruise volume arises with the figures that say
/// why, and the hits behind it.
#[test]
fn the_handling_line_report_leads_with_the_damage() {
    let sc = shipped("scenarios/handling_line.json");
    let out = run_folder(&sc, "handling_line_damage");
    let s: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    let d = &s["damage"];
    let (down, n) = (
        d["apples_downgraded"].as_u64().unwrap(),
        s["apples"].as_array().unwrap().len() as u64,
    );
    let grades: std::collections::BTreeSet<&str> = s["apples"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["grade"].as_str().unwrap())
        .collect();
    println!(
        "{down} of {n} downgraded, {} bruised; grades {grades:?}",
        d["apples_bruised"]
    );
    assert!(grades.len() >= 2, "every apple in one grade: {grades:?}");
    // The point with the most bruise volume, from audit.csv.
    let audit = rows(&out.join("audit.csv"));
    let top = audit
        .iter()
        .max_by(|a, b| {
            num(a, "bruise_volume_mm3_total").total_cmp(&num(b, "bruise_volume_mm3_total"))
        })
        .unwrap();
    let report = applesim::output::report::line_report(&out, "applesim report RUN").unwrap();
    let fruit = report.find("## The fruit").expect("the damage section");
    assert!(
        fruit < report.find("## The run").unwrap(),
        "the report leads with the damage"
    );
    assert!(
        report.contains(&format!("**{down} of {n} apples downgraded**")),
        "{report}"
    );
    let line = report
        .lines()
        .find(|l| l.starts_with("Most of the damage arises at"))
        .expect("names the part");
    assert!(
        line.contains(&format!("**{}**", top["transfer_point"])),
        "{line}"
    );
    let why = report
        .lines()
        .find(|l| l.starts_with("Why: "))
        .expect("says why");
    assert!(why.contains("absorbed") && why.contains(" N "), "{why}");
}

/// Issue 26: a virtual instrumented sphere is not fruit. Sent through the handling line ahead of
/// the apples it is in no fruit figure (no row of apple_contacts.csv or bruises.csv, not among
/// the graded apples, not in the largest peak force), and its own table names the transfer point
/// of every impact, in summary.json, in its impacts file and in the report.
#[test]
fn probes_appear_in_no_fruit_figure() {
    let sc = shipped("scenarios/handling_line_probe.json");
    let out = run_folder(&sc, "handling_line_probe");
    let s: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    let probe = "is";
    for f in ["apple_contacts.csv", "bruises.csv"] {
        let r = rows(&out.join(f));
        assert!(!r.is_empty());
        assert!(r.iter().all(|x| x["apple"] != probe), "{f} names the probe");
    }
    let apples = s["apples"].as_array().unwrap();
    let graded = apples.iter().filter(|a| a["grade"].is_string()).count();
    assert_eq!(
        graded,
        apples.len() - 1,
        "every apple but the probe is graded"
    );
    let p = apples.iter().find(|a| a["name"] == probe).unwrap();
    assert!(p.get("grade").is_none() && p.get("bruises").is_none());
    let per_grade: u64 = s["damage"]["apples_per_grade"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g[1].as_u64().unwrap())
        .sum();
    assert_eq!(per_grade, graded as u64);
    // The largest peak force and every audit figure: of the fruit.
    let contacts = rows(&out.join("contacts.csv"));
    let fruit = |c: &BTreeMap<String, String>| c["a"] != probe && c["b"] != probe;
    let fruit_max = contacts
        .iter()
        .filter(|c| fruit(c))
        .map(|c| num(c, "peak_force_n"))
        .fold(0.0, f64::max);
    let probe_max = contacts
        .iter()
        .filter(|c| !fruit(c))
        .map(|c| num(c, "peak_force_n"))
        .fold(0.0, f64::max);
    println!("largest peak force: fruit {fruit_max:.1} N, probe {probe_max:.1} N");
    assert!(
        probe_max > fruit_max,
        "the probe hits harder: the check has teeth"
    );
    // summary.json in full precision, contacts.csv with 9 significant digits.
    let nine = applesim::output::NumberFormat::default();
    assert_eq!(
        nine.num(s["metrics"]["max_peak_force_n"].as_f64().unwrap()),
        nine.num(fruit_max)
    );
    for r in rows(&out.join("audit.csv")) {
        let at = |c: &BTreeMap<String, String>| c["transfer_point"] == r["transfer_point"];
        let n = contacts.iter().filter(|c| at(c) && fruit(c)).count();
        assert_eq!(num(&r, "contacts") as usize, n, "{r:?}");
    }
    // The probe's impacts name their transfer points everywhere.
    let impacts = s["probes"][0]["impacts"].as_array().unwrap();
    assert!(!impacts.is_empty());
    let file = rows(&out.join("probe_is_impacts.csv"));
    assert_eq!(file.len(), impacts.len());
    for (i, f) in impacts.iter().zip(&file) {
        let tp = i["transfer_point"].as_str().unwrap();
        assert!(!tp.is_empty(), "{i}");
        assert_eq!(tp, f["transfer_point"]);
    }
    let report = applesim::output::report::line_report(&out, "applesim report RUN").unwrap();
    let table = report.split("## Instrumented spheres").nth(1).unwrap();
    let rows_md: Vec<&str> = table
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| impact"))
        .collect();
    assert_eq!(rows_md.len(), impacts.len());
    for l in rows_md {
        let cells: Vec<&str> = l.split('|').map(str::trim).collect();
        assert!(!cells[5].is_empty(), "{l}");
    }
}

/// A sensor ball (89 mm, 0.3 kg, G 10 MPa, nu 0.4) dropped on steel at 2 m/s without gravity,
/// ke = 0.09: its impact table reports Hertz's P_max / (m g) and (1 + sqrt(ke)) v0. Sampled at
/// 1 MHz (every 1 us step) it reads them within 1 %. At the default 10 kHz (period T) the peak
/// is read low by at most 1 - cos(pi / (2 n)) for a loading n samples long (a sample lies at
/// most half a period from the peak of a sine-like pulse), and the velocity change is off by at
/// most (1 - ke) P_max T / (2 m) plus the trapezoid's own error: eq. 12's force drops from P_max
/// to about ke P_max as the overlap turns (the tanh switches within |du/dt| ~ 1 / lambda), and
/// the trapezoid between the samples either side of that drop counts it as a ramp.
#[test]
fn the_instrumented_sphere_reads_peak_g_and_velocity_change_of_the_closed_forms() {
    let (d, m, g_mod, nu, v0) = (0.089, 0.3, 1.0e7, 0.4, 2.0);
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.gravity_m_s2 = [0.0; 3];
    sc.contact.ke = Some(0.09);
    sc.time_step_s = applesim::scenario::TimeStep::Fixed(1e-6);
    sc.duration_s = 0.01;
    sc.materials.insert(
        "sensor".into(),
        serde_json::from_str(&format!(
            r#"{{"shear_modulus_pa": {g_mod}, "poisson_ratio": {nu}}}"#
        ))
        .unwrap(),
    );
    let probe = |rate: f64| AppleSpec {
        name: "is".into(),
        material: "sensor".into(),
        diameter_m: d,
        height_m: None,
        rotation: None,
        mass_kg: Some(m),
        position_m: [0.0, 0.0, d / 2.0 + 1e-5],
        velocity_m_s: [0.0, 0.0, -v0],
        angular_velocity_rad_s: [0.0; 3],
        on: None,
        probe: Some(ProbeSpec {
            sample_rate_hz: rate,
            ..ProbeSpec::default()
        }),
    };
    let k = ode::hertz_k(g_mod, nu, 8.1e10, 0.28, d / 2.0);
    let (_, p_max, t_h, _) = ode::elastic_closed_form(m, v0, k, d / 2.0);
    let want_g = p_max / (m * STANDARD_GRAVITY);
    let want_dv = (1.0 + 0.09f64.sqrt()) * v0;
    for rate in [1e6, 1e4] {
        sc.apples = vec![probe(rate)];
        let out = run_folder(&sc, &format!("probe_{rate}"));
        let imp = rows(&out.join("probe_is_impacts.csv"));
        assert_eq!(imp.len(), 1, "one impact at {rate} Hz: {imp:?}");
        let i = &imp[0];
        assert_eq!(i["transfer_point"], "floor");
        let (g, dv) = (num(i, "peak_g"), num(i, "velocity_change_m_s"));
        println!(
            "{rate} Hz: peak {g:.3} g (closed form {want_g:.3}), dv {dv:.4} m/s ({want_dv:.4}); pulse {:.3} ms",
            1e3 * num(i, "duration_s")
        );
        if rate == 1e6 {
            // README: peak g within 0.001 % at 1 MHz (266.553 against 266.555); the velocity
            // change 2.60000 against 2.6: both at the README's 0.001 %, the looser of the two
            // printed figures (twice the peak's -0.00075 % is 0.0015 %).
            assert_ref("probe peak g", g, want_g, 1e-5, "closed form");
            assert_ref("probe velocity change", dv, want_dv, 1e-5, "closed form");
        } else {
            // Loading lasts t_H / 2 (the peak is unchanged by eq. 12 at lambda v0 >> 1).
            let n = 0.5 * t_h * rate;
            let bound = 1.0 - (std::f64::consts::PI / (2.0 * n)).cos();
            println!(
                "  {n:.1} samples to the peak: under-read at most {:.2} %",
                100.0 * bound
            );
            assert!(
                g <= want_g * (1.0 + 1e-9) && g >= want_g * (1.0 - bound),
                "{g} {want_g} {bound}"
            );
            let drop = 0.5 * (1.0 - 0.09) * p_max / m / rate;
            println!(
                "  velocity change off by {:+.4} m/s; the drop at the peak allows {drop:.4} m/s",
                dv - want_dv
            );
            assert!((dv - want_dv).abs() <= drop, "{dv} {want_dv} {drop}");
        }
        let trace = rows(&out.join("probe_is_trace.csv"));
        let top = trace
            .iter()
            .map(|r| num(r, "acceleration_g"))
            .fold(0.0, f64::max);
        assert_eq!(top, g, "the table's peak is the trace's largest sample");
    }
}
