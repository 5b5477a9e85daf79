//! The three normal damping models of issue 19 (docs/physics.md section 11) against closed forms
//! and an independent RK4 integration of m u'' = m g_n - P(u, u') (tests/common/ode.rs: each law
//! written there from its formula, calling nothing of the crate; each reference checks its own
//! convergence):
//!
//! - `eq12`: P = H [1 + ke + (1 - ke) tanh(lambda u')] / 2 (physics.md section 3);
//! - `eq12-elastic-rest`: P = H [1 - (1 - ke) tanh(lambda max(-u', 0))];
//! - `viscoelastic` (LIGGGHTS `model hertz`, `limitForce on`): P = max(0, H + c u'),
//!   c = -2 sqrt(5/6) beta sqrt(2 E* sqrt(R* u) m*), beta = ln e / sqrt(ln^2 e + pi^2);
//!
//! H = k u^(3/2). The tolerance on the restitution is 0.5 %; peak force and contact time
//! are held to the same. The drops are the Fig. 1 apple (D 80 mm, G 1.1 MPa, nu 0.18, 0.107 kg)
//! on steel at 0.5 and 1 m/s, with and without gravity, at dt 2e-6 s (3 000-11 000 steps per
//! contact; the errors fall linearly with dt: at 1e-5 s the worst restitution is 0.39 % off, the
//! elastic-rest law at lambda v0 = 10 with gravity). The static overlaps are checked after 2.5 s
//! at dt 1e-4 s.

use crate::common;
use applesim::record::events::ContactEvent;
use applesim::scenario::models::Damping;
use common::ode;
use common::*;

const M: f64 = 0.107;
const R: f64 = 0.04;
const G: f64 = 9.81;
/// Fig. 1 apple and steel as (shear modulus, Poisson ratio).
const APPLE: (f64, f64) = (1.1e6, 0.18);
const STEEL: (f64, f64) = (8.1e10, 0.28);

#[derive(Clone, Copy, Debug)]
enum Model {
    Eq12 { ke: f64, lambda: f64 },
    ElasticRest { ke: f64, lambda: f64 },
    Visco { e: f64 },
}

/// Sets a scenario's `contact` to `model`.
fn set_model(sc: &mut applesim::scenario::Scenario, model: Model) {
    match model {
        Model::Eq12 { ke, lambda } | Model::ElasticRest { ke, lambda } => {
            sc.contact.damping = match model {
                Model::Eq12 { .. } => Damping::Eq12,
                _ => Damping::Eq12ElasticRest,
            };
            sc.contact.ke = Some(ke);
            sc.contact.lambda_s_m = Some(lambda);
            sc.contact.restitution = None;
        }
        Model::Visco { e } => {
            sc.contact.damping = Damping::Viscoelastic;
            sc.contact.ke = None;
            sc.contact.lambda_s_m = None;
            sc.contact.restitution = Some(e);
        }
    }
}

/// The shipped Fig. 1 drop (no rolling resistance) with `model`, touching the plate at t = 0 at
/// `v0`.
fn drop(model: Model, v0: f64, gravity: bool, dt: f64) -> ContactEvent {
    let mut sc = shipped("scenarios/drop_on_steel.json");
    set_model(&mut sc, model);
    sc.apples[0].position_m = [0.0, 0.0, R];
    sc.apples[0].velocity_m_s = [0.0, 0.0, -v0];
    if !gravity {
        sc.gravity_m_s2 = [0.0; 3];
    }
    sc.time_step_s = dt.into();
    sc.duration_s = 0.04;
    sc.output.sample_interval_s = Some(0.01);
    sc.output.force_history = Some(false.into());
    sc.model.sleep.enabled = false;
    let (r, _) = run(&sc);
    // Under gravity a slow rebound lands again: the first impact is the one compared.
    assert!(
        r.events[0].t_end_s.is_some(),
        "{model:?} v0 {v0}: no lift-off"
    );
    r.events[0].clone()
}

/// The RK4 reference of the same drop.
fn reference(model: Model, v0: f64, gravity: bool) -> ode::Impact {
    let k = ode::fig1_k();
    let g_n = if gravity { G } else { 0.0 };
    match model {
        Model::Eq12 { ke, lambda } => ode::Setup {
            mass_kg: M,
            k,
            r_star_m: R,
            ke,
            lambda_s_m: lambda,
            g_n,
        }
        .impact(v0, 1.0),
        Model::ElasticRest { ke, lambda } => {
            let f = ode::elastic_rest_law(k, ke, lambda);
            ode::converged_impact_of_law(&f, M, k, R, g_n, v0, 1.0)
        }
        Model::Visco { e } => {
            let e_star = ode::e_star(APPLE.0, APPLE.1, STEEL.0, STEEL.1);
            let f = ode::viscoelastic_law(e_star, R, M, e);
            ode::converged_impact_of_law(&f, M, k, R, g_n, v0, 1.0)
        }
    }
}

/// One drop against its RK4 at dt 2e-6 s: restitution, peak force and contact time within 0.5 %
/// (the tolerance on the restitution) and within twice `stated` (the model's worst error
/// as docs/physics.md 11.1 states it); returns the run's event.
fn check_against_rk4(model: Model, v0: f64, gravity: bool, stated: f64) -> ContactEvent {
    let ev = drop(model, v0, gravity, 2e-6);
    let rk = reference(model, v0, gravity);
    let what = format!("{model:?} v0 {v0} gravity {gravity}");
    let pairs = [
        (
            "restitution",
            ev.restitution.unwrap(),
            rk.rebound_m_s.unwrap() / v0,
        ),
        ("peak force", ev.peak_force_n, rk.peak_force_n),
        (
            "contact time",
            ev.duration_s.unwrap(),
            rk.contact_time_s.unwrap(),
        ),
    ];
    for (name, got, want) in pairs {
        assert!(
            rel(got, want) <= 5e-3,
            "{what}: {name} beyond the issue's 0.5 %"
        );
        assert_ref(&format!("{what}: {name}"), got, want, 2.0 * stated, "RK4");
    }
    ev
}

/// Eq. 12 (section 3): restitution, peak and contact time against RK4 for ke = 0.09 and 0.4225
/// (e -> 0.3 and 0.65, the paper's apples and the Luli apple-apple value), lambda = 1000 s/m
/// (lambda v0 >> 1) and 10 s/m (lambda v0 = 5 and 10), 0.5 and 1 m/s, with and without gravity:
/// within 0.5 % (the issue) and 0.04 % (stated; measured 0.036 %, the restitution). Without
/// gravity at lambda v0 >> 1 the closed form e = sqrt(ke) within 0.006 % (stated; measured
/// 0.004 %). Each measured figure checked at twice its value.
#[test]
fn eq12_against_rk4_and_sqrt_ke() {
    for ke in [0.09, 0.4225] {
        for lambda in [1000.0, 10.0] {
            for v0 in [0.5, 1.0] {
                for gravity in [false, true] {
                    let ev = check_against_rk4(Model::Eq12 { ke, lambda }, v0, gravity, 0.036e-2);
                    if lambda == 1000.0 && !gravity {
                        assert_ref(
                            "e = sqrt(ke)",
                            ev.restitution.unwrap(),
                            ke.sqrt(),
                            2.0 * 0.004e-2,
                            "closed form",
                        );
                    }
                }
            }
        }
    }
}

/// Eq. 12's elastic-at-rest variant: the same grid against RK4, within 0.5 % (the issue) and
/// 0.08 % (stated; measured 0.076 %, the restitution at lambda v0 = 10 with gravity). At dt 1e-5 s
/// that case is still within the 0.5 % (stated 0.39 %). Closed forms without gravity:
/// e = sqrt(ke) at lambda v0 >> 1 (section 3's argument: loading on H, unloading on ke H), within
/// 0.006 % (stated; measured 0.0054 %); and, its loading being elastic whatever ke and lambda, the
/// elastic peak force P_max = k u_max^(3/2), u_max = (5 m v0^2 / (4 k))^(2/5) (physics.md
/// section 4), within 0.0001 % (stated; measured 0.00005 %). Each measured figure checked at
/// twice its value. And the RK4 figures of docs/physics.md 11.1 (ke 0.09, no gravity, +-1 digit): this
/// law returns 0.428 at lambda v0 = 5 and 0.345 at 10, eq. 12 0.394 and 0.332.
#[test]
fn eq12_elastic_rest_against_rk4_and_closed_forms() {
    for ke in [0.09, 0.4225] {
        for lambda in [1000.0, 10.0] {
            for v0 in [0.5, 1.0] {
                for gravity in [false, true] {
                    let ev =
                        check_against_rk4(Model::ElasticRest { ke, lambda }, v0, gravity, 0.076e-2);
                    if !gravity {
                        let (_, p_max, _, _) = ode::elastic_closed_form(M, v0, ode::fig1_k(), R);
                        assert_ref(
                            "elastic peak force",
                            ev.peak_force_n,
                            p_max,
                            2.0 * 0.00005e-2,
                            "closed form",
                        );
                        if lambda == 1000.0 {
                            assert_ref(
                                "e = sqrt(ke)",
                                ev.restitution.unwrap(),
                                ke.sqrt(),
                                2.0 * 0.0054e-2,
                                "closed form",
                            );
                        }
                    }
                }
            }
        }
    }
    // At dt 1e-5 s (the scenarios' usual step for drops), the worst case of the grid.
    let model = Model::ElasticRest {
        ke: 0.09,
        lambda: 10.0,
    };
    let e = drop(model, 1.0, true, 1e-5).restitution.unwrap();
    let want = reference(model, 1.0, true).rebound_m_s.unwrap();
    assert_ref("dt 1e-5 s: restitution", e, want, 5e-3, "RK4");
    assert!(rel(e, want) <= 0.39e-2 + 0.005e-2);
    // The finite lambda v0 figures of 11.1 (RK4 only, no gravity, v0 1 m/s).
    for (lambda_v0, elastic_rest, eq12) in [(5.0, 0.428, 0.394), (10.0, 0.345, 0.332)] {
        let er = reference(
            Model::ElasticRest {
                ke: 0.09,
                lambda: lambda_v0,
            },
            1.0,
            false,
        );
        let e12 = reference(
            Model::Eq12 {
                ke: 0.09,
                lambda: lambda_v0,
            },
            1.0,
            false,
        );
        let (er, e12) = (er.rebound_m_s.unwrap(), e12.rebound_m_s.unwrap());
        println!("lambda v0 {lambda_v0}: elastic-rest e {er:.4}, eq12 e {e12:.4}");
        assert!((er - elastic_rest).abs() <= 1e-3 && (e12 - eq12).abs() <= 1e-3);
    }
}

/// LIGGGHTS's viscoelastic Hertz: restitution, peak force and contact time against RK4 for
/// `restitution` 0.3 and 0.65, 0.5 and 1 m/s, with and without gravity: within 0.5 % (the issue)
/// and 0.025 % (stated; measured 0.0247 %, a peak force), checked at twice the measured. Closed form
/// without gravity: the law is scale-free (c grows as u^(1/4): rescaling u and t leaves
/// c / sqrt(k m) alone), so e does not depend on v0: the two speeds within 5e-6 (stated;
/// measured 3.1e-6), checked at twice the measured.
#[test]
fn viscoelastic_against_rk4() {
    for e in [0.3, 0.65] {
        let mut no_gravity = Vec::new();
        for v0 in [0.5, 1.0] {
            for gravity in [false, true] {
                let ev = check_against_rk4(Model::Visco { e }, v0, gravity, 0.0247e-2);
                if !gravity {
                    no_gravity.push(ev.restitution.unwrap());
                }
            }
        }
        println!(
            "restitution {e}: e {:.5} at 0.5 m/s, {:.5} at 1 m/s",
            no_gravity[0], no_gravity[1]
        );
        let spread = (no_gravity[0] - no_gravity[1]).abs();
        println!("restitution {e}: the two speeds {spread:.2e} apart");
        assert!(spread <= 2.0 * 3.1e-6);
    }
}

/// What the viscoelastic law's `restitution` means (docs/physics.md 11.1), by RK4 without gravity
/// (scale-free: one speed serves): without the clamp at zero force the law returns exactly the
/// restitution asked for (to 1e-5 from 0.1 to 0.95); with the clamp (LIGGGHTS `limitForce on`, and
/// applesim: a contact never pulls) the apple leaves the force early and rebounds faster: 0.3 ->
/// 0.3971, 0.65 -> 0.6747 (the table of 11.1, +-1 in the last digit). The same RK4 reproduces
/// LIGGGHTS 3.8's own drops of docs/liggghts_models.md (E 2.6 MPa apple, 800 kg/m^3, D 80 mm, on
/// 200 GPa steel, 1 m/s, no gravity, dt 1e-6: e 0.3 -> 71.380 N, 9.1628 ms with overlap, e 0.3971;
/// e 0.65 -> 81.280 N, 8.3049 ms, 0.6747) within 0.011 % (measured 0.0102 %), and so does applesim
/// (dt 2e-6 s) within 0.01 % (measured 0.0088 %); both checked at 0.02 %.
#[test]
fn viscoelastic_restitution_is_raised_by_the_clamp() {
    let e_star = ode::e_star(APPLE.0, APPLE.1, STEEL.0, STEEL.1);
    let k = ode::fig1_k();
    let table = [
        (0.1, 0.2527),
        (0.2, 0.3249),
        (0.3, 0.3971),
        (0.4, 0.4720),
        (0.5, 0.5503),
        (0.65, 0.6747),
        (0.8, 0.8081),
        (0.9, 0.9020),
        (0.95, 0.9505),
    ];
    for (e_in, e_clamped) in table {
        let clamped = ode::viscoelastic_law(e_star, R, M, e_in);
        let got = ode::converged_impact_of_law(&clamped, M, k, R, 0.0, 1.0, 1.0)
            .rebound_m_s
            .unwrap();
        // The same law without the clamp (it may pull while the apple leaves).
        let beta = ode::liggghts_beta(e_in);
        let free = move |u: f64, w: f64| {
            if u <= 0.0 {
                return 0.0;
            }
            let c =
                -2.0 * (5.0f64 / 6.0).sqrt() * beta * (2.0 * e_star * (R * u).sqrt() * M).sqrt();
            k * u * u.sqrt() + c * w
        };
        let unclamped = ode::converged_impact_of_law(&free, M, k, R, 0.0, 1.0, 1.0)
            .rebound_m_s
            .unwrap();
        println!(
            "restitution {e_in}: clamped e {got:.5} (table {e_clamped}), unclamped {unclamped:.6}"
        );
        assert!((unclamped - e_in).abs() < 1e-5, "unclamped {unclamped}");
        assert!(
            (got - e_clamped).abs() <= 1e-4,
            "clamped {got}, table {e_clamped}"
        );
    }
    // LIGGGHTS 3.8 (docs/liggghts_models.md, section (a), rows without gravity at 1 m/s): the
    // stored runs' figures (tests/data/liggghts/results.json, full precision). The RK4 and
    // applesim (dt 2e-6 s) reproduce them within 0.0095 % (docs/physics.md 11.1; measured
    // 0.0087 % and 0.0094 %), checked at twice that.
    let stored: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(common::repo("tests/data/liggghts/results.json")).unwrap(),
    )
    .unwrap();
    let lig = |name: &str| {
        let r = stored["drop"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["name"] == name)
            .unwrap();
        let f = |k: &str| r[k].as_f64().unwrap();
        (
            f("peak_force_n"),
            f("contact_time_overlap_s"),
            f("restitution_separation"),
        )
    };
    let (e_apple, nu_apple, e_steel, nu_steel) = (2.6e6, 0.18, 2.0e11, 0.3);
    let g_of = |e: f64, nu: f64| e / (2.0 * (1.0 + nu));
    let e_star = ode::e_star(
        g_of(e_apple, nu_apple),
        nu_apple,
        g_of(e_steel, nu_steel),
        nu_steel,
    );
    let mass = 800.0 * 4.0 / 3.0 * std::f64::consts::PI * R.powi(3);
    let k = 4.0 / 3.0 * e_star * R.sqrt();
    for (e_in, (peak, t_c, e_out)) in [
        (0.3, lig("drop_v1_e0.3_nog")),
        (0.65, lig("drop_v1_e0.65_nog")),
    ] {
        let law = ode::viscoelastic_law(e_star, R, mass, e_in);
        let rk = ode::converged_impact_of_law(&law, mass, k, R, 0.0, 1.0, 1.0);
        let what = format!("LIGGGHTS drop, restitution {e_in}");
        assert_ref(
            &format!("{what}: RK4 peak"),
            rk.peak_force_n,
            peak,
            2.0 * 0.0095e-2,
            "LIGGGHTS",
        );
        assert_ref(
            &format!("{what}: RK4 contact time"),
            rk.contact_time_s.unwrap(),
            t_c,
            2.0 * 0.0095e-2,
            "LIGGGHTS",
        );
        assert_ref(
            &format!("{what}: RK4 e"),
            rk.rebound_m_s.unwrap(),
            e_out,
            2.0 * 0.0095e-2,
            "LIGGGHTS",
        );
        let mut sc = shipped("scenarios/drop_on_steel.json");
        set_model(&mut sc, Model::Visco { e: e_in });
        sc.materials.insert(
            "apple".into(),
            serde_json::from_value(serde_json::json!({"youngs_modulus_pa": e_apple, "poisson_ratio": nu_apple, "density_kg_m3": 800})).unwrap(),
        );
        sc.materials.insert(
            "steel".into(),
            serde_json::from_value(
                serde_json::json!({"youngs_modulus_pa": e_steel, "poisson_ratio": nu_steel}),
            )
            .unwrap(),
        );
        sc.apples[0].mass_kg = None;
        sc.apples[0].position_m = [0.0, 0.0, R];
        sc.apples[0].velocity_m_s = [0.0, 0.0, -1.0];
        sc.gravity_m_s2 = [0.0; 3];
        sc.time_step_s = 2e-6.into();
        sc.duration_s = 0.02;
        sc.output.force_history = Some(false.into());
        let (r, _) = run(&sc);
        let ev = &r.events[0];
        assert_ref(
            &format!("{what}: applesim peak"),
            ev.peak_force_n,
            peak,
            2.0 * 0.0095e-2,
            "LIGGGHTS",
        );
        assert_ref(
            &format!("{what}: applesim contact time"),
            ev.duration_s.unwrap(),
            t_c,
            2.0 * 0.0095e-2,
            "LIGGGHTS",
        );
        assert_ref(
            &format!("{what}: applesim e"),
            ev.restitution.unwrap(),
            e_out,
            2.0 * 0.0095e-2,
            "LIGGGHTS",
        );
    }
}

/// Static overlap (docs/physics.md 11.2) of an apple resting on steel: eq. 12 carries
/// (1 + ke)/2 of Hertz at rest, u = (2 m g / ((1 + ke) k))^(2/3); the elastic-rest variant and the
/// viscoelastic law the whole, u = (m g / k)^(2/3). For the Fig. 1 apple (0.107 kg) and a 0.2 kg
/// apple of the same size and flesh, ke 0.09: within 0.5 % (the issue) and 3.7e-8 (stated, the
/// 0.2 kg eq12 apple; checked at twice that; 1.5e-6 before resting contacts' eq. 12 step mean took
/// the support into account) after 2.5 s at dt 1e-4 s, released at rest 1 % below its sag.
/// Also the doc's table of 11.2 (the closed forms, +-1 in the last digit) and its k.
#[test]
fn static_overlap_of_each_model() {
    let k = ode::fig1_k();
    let ke = 0.09;
    assert!((k - 7.154e5).abs() <= 0.001e5, "k {k}");
    // (mass, model, overlap mm, u/R %, contact radius mm, mean and peak pressure kPa) as
    // docs/physics.md 11.2.
    let doc = [
        (0.107, "eq12", 0.1935, 0.48, 2.782, 43.2, 64.7),
        (0.107, "elastic", 0.1291, 0.32, 2.273, 64.7, 97.0),
        (0.2, "eq12", 0.2936, 0.73, 3.427, 53.2, 79.8),
        (0.2, "elastic", 0.1959, 0.49, 2.799, 79.7, 119.5),
    ];
    for (m, kind, u_doc, ratio_doc, a_doc, p_doc, p0_doc) in doc {
        let f = if kind == "eq12" {
            0.5 * (1.0 + ke)
        } else {
            1.0
        };
        let u = (m * G / (f * k)).powf(2.0 / 3.0);
        let a = (R * u).sqrt();
        let p = m * G / (std::f64::consts::PI * a * a);
        println!(
            "{m} kg {kind}: u {:.4} mm ({:.2} % of R), a {:.3} mm, p_mean {:.1} kPa, p0 {:.1} kPa",
            u * 1e3,
            100.0 * u / R,
            a * 1e3,
            p * 1e-3,
            1.5 * p * 1e-3
        );
        assert!((u * 1e3 - u_doc).abs() <= 1e-4 && (100.0 * u / R - ratio_doc).abs() <= 0.01);
        assert!((a * 1e3 - a_doc).abs() <= 1e-3);
        assert!((p * 1e-3 - p_doc).abs() <= 0.1 && (1.5 * p * 1e-3 - p0_doc).abs() <= 0.1);
    }
    // The ratios of 11.2: eq. 12 against elastic Hertz at ke 0.09 (and the sag at 0.4225).
    let sag = (2.0 / (1.0 + ke)).powf(2.0 / 3.0);
    println!(
        "eq12 / elastic: sag {sag:.4}, radius {:.4}, pressure {:.4}",
        sag.sqrt(),
        1.0 / sag
    );
    assert!((sag - 1.50).abs() <= 0.01 && (sag.sqrt() - 1.22).abs() <= 0.01);
    assert!((1.0 / sag - 0.667).abs() <= 0.001);
    assert!(((2.0f64 / 1.4225).powf(2.0 / 3.0) - 1.26).abs() <= 0.01);
    for m in [0.107, 0.2] {
        for model in [
            Model::Eq12 { ke, lambda: 1000.0 },
            Model::ElasticRest { ke, lambda: 1000.0 },
            Model::Visco { e: 0.3 },
        ] {
            let f = match model {
                Model::Eq12 { .. } => 0.5 * (1.0 + ke),
                _ => 1.0,
            };
            let u_cf = (m * G / (f * k)).powf(2.0 / 3.0);
            let mut sc = shipped("scenarios/drop_on_steel.json");
            set_model(&mut sc, model);
            sc.apples[0].mass_kg = Some(m);
            sc.apples[0].position_m = [0.0, 0.0, R - 1.01 * u_cf];
            sc.apples[0].velocity_m_s = [0.0; 3];
            sc.time_step_s = 1e-4.into();
            sc.duration_s = 2.5;
            sc.output.sample_interval_s = Some(0.5);
            sc.output.force_history = Some(false.into());
            sc.model.sleep.enabled = false;
            let (_, s) = run(&sc);
            let u = R - s.of(0).last().unwrap().1.position.z;
            assert_ref(
                &format!("{m} kg, {model:?}: static overlap"),
                u,
                u_cf,
                5e-3,
                "closed form",
            );
            println!(
                "{m} kg, {model:?}: {:.2e} off the closed form",
                rel(u, u_cf)
            );
            assert!(rel(u, u_cf) <= 2.0 * 3.7e-8);
        }
    }
}

/// An apple released at rest at exactly its closed-form sag (the Fig. 1 apple on steel): its
/// largest departure from the sag over 1 s, per damping and step (docs/physics.md 11.2), each
/// checked at twice its figure: viscoelastic 1.0e-14 at both steps (it does not move: the
/// rounding of its start height); eq12 0.023 % at dt 1e-4 s and 0.00025 % at 1e-5 s;
/// eq12-elastic-rest 0.87 % and 0.010 %. The eq. 12 laws sink in the contact's first
/// milliseconds, while it still counts as an impact and keeps the paper's law (its step mean
/// counts the contact's own force alone: next test), then rise back to the sag: at 1 s within
/// 1.2e-7 of it at 1e-4 s and 5.5e-10 at 1e-5 s. (Before resting contacts' step mean took the
/// support into account: 20 % / 25 % at 1e-4 s, 2.7 % / 3.0 % at 1e-5 s.)
#[test]
fn released_at_its_sag_an_apple_stays_there() {
    let k = ode::fig1_k();
    let ke = 0.09;
    let mut failures = Vec::new();
    // (dt, the figure at 1 s for the eq. 12 laws).
    for (dt, at_1s) in [(1e-4, 1.2e-7), (1e-5, 5.5e-10)] {
        // (model, the stated largest departure, relative).
        for (model, stated) in [
            (Model::Visco { e: 0.3 }, 1.0e-14),
            (
                Model::Eq12 { ke, lambda: 1000.0 },
                if dt == 1e-4 { 0.023e-2 } else { 0.00025e-2 },
            ),
            (
                Model::ElasticRest { ke, lambda: 1000.0 },
                if dt == 1e-4 { 0.87e-2 } else { 0.010e-2 },
            ),
        ] {
            let f = match model {
                Model::Eq12 { .. } => 0.5 * (1.0 + ke),
                _ => 1.0,
            };
            let u_cf = (M * G / (f * k)).powf(2.0 / 3.0);
            let mut sc = shipped("scenarios/drop_on_steel.json");
            set_model(&mut sc, model);
            sc.apples[0].position_m = [0.0, 0.0, R - u_cf];
            sc.apples[0].velocity_m_s = [0.0; 3];
            sc.time_step_s = dt.into();
            sc.duration_s = 1.0;
            sc.output.sample_interval_s = Some(1e-3);
            sc.output.force_history = Some(false.into());
            sc.model.sleep.enabled = false;
            let (_, s) = run(&sc);
            let off: Vec<(f64, f64)> = s
                .of(0)
                .iter()
                .map(|(t, a)| (*t, ((R - a.position.z) / u_cf - 1.0).abs()))
                .collect();
            let worst = off.iter().map(|p| p.1).fold(0.0, f64::max);
            let end = off.last().unwrap().1;
            println!(
                "dt {dt} {model:?}: largest departure from the sag over 1 s {worst:.3e} ({:.5} %), at 1 s {end:.3e}",
                100.0 * worst
            );
            if worst > 2.0 * stated {
                failures.push(format!(
                    "{model:?} at dt {dt}: {worst:.3e} off its sag (stated {stated:e})"
                ));
            }
            if !matches!(model, Model::Visco { .. }) && end > 2.0 * at_1s {
                failures.push(format!(
                    "{model:?} at dt {dt}: {end:.3e} off its sag at 1 s (stated {at_1s:e})"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// The eq. 12 laws average their tanh over the step, from the rate du/dt now to a predicted
/// du/dt_next = du/dt + (a_free - P / m_n) dt. A resting contact gets the free relative
/// acceleration a_free the layer measured over the last step (here gravity, g): at its sag, or
/// approaching it, its force is then at least m g (measured: eq12 1.0000, 1.0083 and 1.0832 m g
/// at du/dt = 0, 1e-5 and 1e-4 m/s; eq12-elastic-rest 1.0000). An impact keeps the paper's law as
/// validated (a_free = 0: the contact's own force alone), so a contact born at rest at its sag
/// gets, on its first step, 0.643 m g (eq12) and 0.611 m g (eq12-elastic-rest) at dt 1e-4 s, 0.959
/// and 0.955 m g at 1e-5 s (golden, to the printed digit): what sinks the apple of the previous
/// test in its first milliseconds. (Before the fix a resting contact got the impact's figures.)
#[test]
fn approaching_or_at_rest_the_force_is_at_least_the_static_force() {
    use applesim::contact::{self, *};
    use applesim::math::Vec3;
    let apple = Material::from_shear(APPLE.0, APPLE.1, Some(800.0)).unwrap();
    let steel = Material::from_shear(STEEL.0, STEEL.1, None).unwrap();
    let ke = 0.09;
    let k = ode::fig1_k();
    let mut worst = f64::INFINITY;
    // (damping, the static factor, the impact's first step at dt 1e-4 and 1e-5 s in m g).
    for (damping, f, first) in [
        (DampingModel::Eq12, 0.5 * (1.0 + ke), [0.643, 0.959]),
        (DampingModel::Eq12ElasticRest, 1.0, [0.611, 0.955]),
    ] {
        let law = PairLaw::new(&apple, &steel, 0.3, ke, 1000.0).with_models(SubModels {
            damping,
            ..SubModels::default()
        });
        let consts = ContactConstants::new(&law, R, M, M);
        let u = (M * G / (f * k)).powf(2.0 / 3.0);
        for (dt, first) in [1e-4, 1e-5].into_iter().zip(first) {
            let force = |resting: bool, rate: f64, free_accel: f64| {
                let kin = ContactKinematics {
                    normal: Vec3::Z,
                    overlap_m: u,
                    rel_velocity: Vec3::new(0.0, 0.0, -rate),
                    resting,
                    free_accel,
                    history_damping_limit_1_s: f64::INFINITY,
                };
                let mut xi = Vec3::ZERO;
                let r = contact::evaluate(
                    &law,
                    LawParts::default(),
                    &consts,
                    &kin,
                    &mut xi,
                    0.5 / dt,
                    dt,
                );
                r.normal_force_n / (M * G)
            };
            // Resting, gravity pressing the apple onto the floor (-g . n).
            for rate in [0.0, 1e-5, 1e-4] {
                let ratio = force(true, rate, G);
                println!("{damping:?} dt {dt}, resting, du/dt +{rate:e}: P = {ratio:.4} m g");
                worst = worst.min(ratio);
            }
            // The impact's first step at the sag (the layer passes a_free = 0).
            let ratio = force(false, 0.0, 0.0);
            println!("{damping:?} dt {dt}, an impact's first step at the sag: P = {ratio:.4} m g");
            assert!(
                (ratio - first).abs() <= 1e-3,
                "{damping:?} dt {dt}: {ratio} m g, stated {first}"
            );
        }
    }
    assert!(
        worst >= 1.0 - 1e-9,
        "P = {worst} m g at rest or approaching"
    );
}
