//! The viewer's page (issue 21) in a real browser: Debian's Chromium, headless, driven over the
//! DevTools protocol by `headless_chrome`, as a person's browser would show it. The page loads
//! from disk with no console error, its scene holds the run's apples and surface parts, moving
//! the time slider (a real mouse click on it, the End key) puts the apples where bodies.csv has
//! them (within the quantisation step), clicking an apple shows its contacts, switching the
//! colour changes the rendered pixels, and a screenshot is not blank. Spheroidal apples (issue
//! 29) are drawn as their ellipsoids, turned by bodies.csv's orientations, their silhouettes
//! those of the closed form.
//!
//! Chromium is required, never skipped: without it the test fails and says how to install it
//! (`tools/test`, the README's test command, installs it when missing). `APPLESIM_CHROMIUM`
//! names another binary.

use crate::view_session;
use view_session::*;

use headless_chrome::browser::tab::point::Point;
use headless_chrome::protocol::cdp::Page::CaptureScreenshotFormatOption;
use std::collections::BTreeMap;
use std::path::Path;

#[test]
fn handling_line_in_chromium() {
    let dir = tmp("handling_line");
    let run_dir = dir.join("run");
    let o = run(&[
        "run",
        "scenarios/handling_line.json",
        "--out",
        run_dir.to_str().unwrap(),
        "--view",
    ]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("view.html"));
    let page = run_dir.join("view.html");
    let (samples, names) = bodies(&run_dir);
    let parts = surface_parts(&run_dir);
    assert_eq!(parts, 7); // belt, chute, bin floor and four walls

    let s = launch("handling_line");
    let load = s.open(&page, "");
    eprintln!("handling line page loaded in {:.2} s", load.as_secs_f64());

    // The scene holds the run's apples and surfaces.
    let counts = s.eval(
        "JSON.stringify({ apples: applesimView.apples.userData.count, surfaces: applesimView.surfaces.length, \
           names: applesimView.data.apples.map(a => a.name), \
           kinds: applesimView.surfaces.map(m => m.userData.kind), \
           frames: applesimView.frameTimes.length, \
           canvas: !!document.querySelector('canvas'), \
           gl: !!applesimView.renderer.getContext() })",
    );
    assert_eq!(counts["apples"], names.len());
    assert_eq!(counts["surfaces"], parts);
    assert_eq!(counts["names"], serde_json::json!(names));
    assert_eq!(counts["frames"], 600);
    assert_eq!(counts["gl"], true);
    let kinds: Vec<&str> = counts["kinds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|k| k.as_str().unwrap())
        .collect();
    assert_eq!(
        kinds,
        ["conveyor", "chute", "bin", "bin", "bin", "bin", "bin"]
    );

    // At t = 0 one apple has been fed in; the first frame is the first sample.
    let t0 = check_positions(&s, &samples, &names);
    assert_eq!(t0, 0.0);

    // Apples are drawn as spheres by a shader on one square each (impostors): alone on the
    // screen, the one apple fed in covers a disc of its projected radius around its centre, not
    // a square, and picking (hover) agrees with the drawing at its rim.
    let one = s.eval(
        "(() => { const V = applesimView, T = V.THREE, c = V.renderer.domElement.getBoundingClientRect(); \
           let i = -1; for (let k = 0; k < V.apples.userData.count; k++) if (V.apples.userData.at(k)[3] > 0) i = k; \
           const a = V.apples.userData.at(i), p = new T.Vector3(a[0], a[1], a[2]); \
           const e = p.clone().add(new T.Vector3().setFromMatrixColumn(V.camera.matrixWorld, 0).multiplyScalar(a[3])); \
           const px = (v) => { v.project(V.camera); return [c.left + (v.x + 1) / 2 * c.width, c.top + (1 - v.y) / 2 * c.height]; }; \
           const [x, y] = px(p), [xe, ye] = px(e); \
           const r = Math.hypot(xe - x, ye - y), clear = [[0, 0], [-3, -3], [3, -3], [-3, 3], [3, 3]] \
             .every(([u, v]) => document.elementFromPoint(x + u * r, y + v * r) === V.renderer.domElement); \
           V.scene.children.forEach((o) => { if (o !== V.apples && !o.isLight) o.visible = false; }); \
           return JSON.stringify([i, x, y, r, window.innerWidth, clear]); })()",
    );
    let (i, x, y, rpx) = (
        one[0].as_u64().unwrap() as usize,
        one[1].as_f64().unwrap(),
        one[2].as_f64().unwrap(),
        one[3].as_f64().unwrap(),
    );
    assert!(rpx > 4.0, "apple {} is {rpx} px across", names[i]);
    assert_eq!(one[5], true, "apple {} is under a panel", names[i]);
    let (px, w, _) = s.screenshot();
    let dpr = w as f64 / one[4].as_f64().unwrap();
    let (mut inside, mut outside) = (0usize, 0usize);
    for (k, p) in px.chunks(4).enumerate() {
        let (qx, qy) = (
            (k % w as usize) as f64 / dpr + 0.5,
            (k / w as usize) as f64 / dpr + 0.5,
        );
        if differs(p, &px[..4]) && (qx - x).abs() < 3.0 * rpx && (qy - y).abs() < 3.0 * rpx {
            if (qx - x).hypot(qy - y) <= 1.1 * rpx + 1.5 {
                inside += 1;
            } else {
                outside += 1;
            }
        }
    }
    let disc = std::f64::consts::PI * rpx * rpx * dpr * dpr;
    assert!(
        inside as f64 > 0.75 * disc && (inside as f64) < 1.3 * disc,
        "apple {} covers {inside} pixels in its disc of {disc:.0}",
        names[i]
    );
    assert_eq!(outside, 0, "pixels drawn outside apple {}'s disc", names[i]);
    eprintln!(
        "apple {} drawn as a disc of {inside} pixels ({disc:.0} for its radius of {rpx:.1} px)",
        names[i]
    );
    s.eval("(() => { applesimView.scene.children.forEach((o) => { o.visible = true; }); return 'true'; })()");
    for (f, over) in [(0.8, true), (1.3, false)] {
        s.tab
            .move_mouse_to_point(Point {
                x: x + f * rpx + if over { 0.0 } else { 2.0 },
                y,
            })
            .unwrap();
        let tip = s.eval(
            "JSON.stringify([document.getElementById('tip').style.display, document.getElementById('tip').textContent])",
        );
        assert_eq!(
            tip[0] == "block"
                && tip[1]
                    .as_str()
                    .unwrap()
                    .starts_with(&format!("{} (", names[i])),
            over,
            "hover at {f} of apple {}'s radius from its centre: {tip}",
            names[i]
        );
    }

    // A click on the slider at 40 % of its width moves the apples to that frame's sample.
    let rect = s.eval(
        "JSON.stringify((r => [r.left, r.top, r.width, r.height])(document.getElementById('slider').getBoundingClientRect()))",
    );
    let r: Vec<f64> = rect
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    s.click(r[0] + 0.4 * r[2], r[1] + r[3] / 2.0);
    let t_mid = check_positions(&s, &samples, &names);
    assert!(
        t_mid > 3.0 && t_mid < 5.0,
        "the click at 40 % of the slider gave t = {t_mid} s"
    );

    // The End key on the focused slider: the last sample, every apple in the bin.
    s.tab.press_key("End").unwrap();
    let t_end = check_positions(&s, &samples, &names);
    assert_eq!(t_end, 10.0);
    let shown = s.eval("JSON.stringify(document.getElementById('counts').textContent)");
    assert!(
        shown.as_str().unwrap().starts_with("20 of 20 apples"),
        "{shown}"
    );

    // Colour switches change the rendered pixels; no screenshot is blank.
    let mut shots = Vec::new();
    for c in ["force", "bruise", "speed", "motion"] {
        s.eval(&format!(
            "(() => {{ const e = document.getElementById('colour'); e.value = '{c}'; \
               e.dispatchEvent(new Event('change')); return JSON.stringify(e.value); }})()"
        ));
        let (px, w, h) = s.screenshot();
        assert!(w >= 800 && h >= 500, "a {w} x {h} viewport");
        let non_bg = drawn_pixels(&px);
        let distinct: std::collections::BTreeSet<[u8; 3]> = px
            .chunks(4)
            .map(|p| [p[0] / 8, p[1] / 8, p[2] / 8])
            .collect();
        assert!(
            non_bg > (w * h / 20) as usize,
            "{c}: nearly blank ({non_bg} pixels off the background)"
        );
        assert!(distinct.len() > 50, "{c}: only {} colours", distinct.len());
        shots.push((c, px));
    }
    for i in 0..shots.len() {
        for j in i + 1..shots.len() {
            let n = changed_pixels(&shots[i].1, &shots[j].1);
            assert!(
                n > 200,
                "colour by {} and by {} differ in only {n} pixels",
                shots[i].0,
                shots[j].0
            );
        }
    }

    // A click on an apple shows its name, size, mass and contacts so far.
    let at = s.eval(
        "(() => { const V = applesimView, p = new V.THREE.Vector3(); \
           const c = V.renderer.domElement.getBoundingClientRect(); \
           let best = null; for (let i = 0; i < V.apples.userData.count; i++) { \
           p.fromArray(V.apples.userData.at(i)).project(V.camera); \
           const x = c.left + (p.x + 1) / 2 * c.width, y = c.top + (1 - p.y) / 2 * c.height; \
           if (document.elementFromPoint(x, y) === V.renderer.domElement && (!best || p.z < best[3])) best = [i, x, y, p.z]; } \
           return JSON.stringify(best); })()",
    );
    let (i, x, y) = (
        at[0].as_u64().unwrap() as usize,
        at[1].as_f64().unwrap(),
        at[2].as_f64().unwrap(),
    );
    // Hovering shows a tip with its name, size and mass.
    s.tab.move_mouse_to_point(Point { x, y }).unwrap();
    let tip = s.eval(
        "JSON.stringify([document.getElementById('tip').style.display, document.getElementById('tip').textContent])",
    );
    assert_eq!(tip[0], "block", "no tip over apple {}", names[i]);
    let tip = tip[1].as_str().unwrap();
    assert!(
        tip.starts_with(&format!("{} (", names[i]))
            && tip.contains(" mm, ")
            && tip.contains(" g, "),
        "{tip}"
    );
    s.click(x, y);
    let info = s.eval(
        "JSON.stringify({ shown: document.getElementById('info').style.display, text: document.getElementById('info').textContent, rows: document.querySelectorAll('#info tr').length })",
    );
    assert_eq!(
        info["shown"], "block",
        "clicking apple {} at ({x}, {y}) showed nothing",
        names[i]
    );
    let text = info["text"].as_str().unwrap();
    assert!(
        text.contains("diameter") && text.contains("mass") && text.contains("contact(s) so far"),
        "{text}"
    );
    assert!(
        info["rows"].as_u64().unwrap() > 1,
        "no contact listed: {text}"
    );
    let clicked = names
        .iter()
        .find(|n| text.starts_with(&format!("{n}:")))
        .expect("the panel names an apple");
    assert_eq!(clicked, &names[i], "clicked at apple {}'s centre", names[i]);
    eprintln!("clicked {clicked}: {}", &text[..text.len().min(160)]);

    let errors = s.errors();
    assert!(errors.is_empty(), "the page reported errors: {errors:?}");
}

/// Every kind of surface is drawn (plane, box, conveyor, flat chute, trough, bin, mesh), with
/// force histories on, and a run without any apple (bodies.csv with its header only) still
/// views, saying so on the page.
#[test]
fn every_surface_kind_and_a_run_without_apples() {
    let dir = tmp("kinds");
    let scenario = serde_json::json!({
        "duration_s": 0.25,
        "time_step_s": 2e-5,
        "gravity_m_s2": [0, 0, -9.81],
        "output": { "sample_interval_s": 0.005, "force_history": true },
        "materials": {
            "apple": { "shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800 },
            "steel": { "youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.28 }
        },
        "contact": { "friction": 0.3, "ke": 0.09, "lambda_s_m": 1000 },
        "apples": [
            { "name": "on-box", "material": "apple", "diameter_m": 0.08, "position_m": [0, 0, 0.3], "velocity_m_s": [0, 0, -2.5] },
            { "name": "on-belt", "material": "apple", "diameter_m": 0.07, "position_m": [0.6, 0, 0.2], "velocity_m_s": [0, 0, -1] },
            { "name": "in-trough", "material": "apple", "diameter_m": 0.075, "position_m": [1.2, 0, 0.2], "velocity_m_s": [0, 0, -1] },
            { "name": "in-bin", "material": "apple", "diameter_m": 0.08, "position_m": [1.8, 0, 0.2], "velocity_m_s": [0, 0, -3] },
            { "name": "on-mesh", "material": "apple", "diameter_m": 0.08, "position_m": [0, 0.8, 0.2], "velocity_m_s": [0, 0, -1] }
        ],
        "surfaces": [
            { "name": "floor", "type": "plane", "material": "steel", "point_m": [0, 0, -0.2], "normal": [0, 0, 1] },
            { "name": "table", "type": "box", "material": "steel", "size_m": [0.3, 0.3, 0.05], "position_m": [0, 0, 0.1] },
            { "name": "belt", "type": "conveyor", "material": "steel", "size_m": [0.4, 0.2, 0.04], "position_m": [0.6, 0, 0.1], "belt_velocity_m_s": -0.3,
              "rotation": { "axis": [0, 0, 1], "angle_deg": 30 } },
            { "name": "slide", "type": "chute", "profile": "flat", "material": "steel", "length_m": 0.4, "width_m": 0.2, "incline_deg": 15, "position_m": [0.6, 0.5, 0.05] },
            { "name": "gutter", "type": "chute", "profile": "trough", "material": "steel", "length_m": 0.4, "radius_m": 0.1, "position_m": [1.2, 0, 0.05] },
            { "name": "crate", "type": "bin", "material": "steel", "inner_size_m": [0.3, 0.3, 0.15], "position_m": [1.8, 0, 0.05] },
            { "name": "plate", "type": "mesh", "material": "steel", "file": "floor_two_triangles.obj", "scale": 0.3, "position_m": [0, 0.8, 0.05] }
        ]
    });
    std::fs::copy(
        "assets/floor_two_triangles.obj",
        dir.join("floor_two_triangles.obj"),
    )
    .unwrap();
    let run_dir = run_scenario(
        &dir,
        "kinds",
        "run",
        &scenario,
        &["--view", "--max-frames", "20"],
    );
    let (samples, names) = bodies(&run_dir);
    assert_eq!(names.len(), 5);

    // The same run without apples: a source that starts after the end.
    let mut empty = scenario.clone();
    empty["apples"] = serde_json::json!([]);
    empty["sources"] = serde_json::json!([{ "name": "late", "material": "apple", "diameter_m": 0.08,
        "position_m": [0, 0, 0.5], "rate_per_s": 1, "start_s": 10, "count": 1 }]);
    let empty_dir = run_scenario(&dir, "empty", "empty", &empty, &["--view"]);
    let text = std::fs::read_to_string(empty_dir.join("bodies.csv")).unwrap();
    assert_eq!(
        text.lines().count(),
        1,
        "bodies.csv should be its header only"
    );

    let s = launch("kinds");
    s.open(&run_dir.join("view.html"), "");
    let v = s.eval(
        "JSON.stringify({ apples: applesimView.apples.userData.count, kinds: applesimView.surfaces.map(m => m.userData.kind), \
           frames: applesimView.frameTimes.length, arrows: applesimView.scene.getObjectsByProperty('type', 'ArrowHelper').length, \
           notes: [...document.querySelectorAll('#notes-list li')].map(l => l.textContent) })",
    );
    assert_eq!(v["apples"], 5);
    assert_eq!(v["frames"], 20);
    assert_eq!(v["arrows"], 3);
    let kinds: Vec<&str> = v["kinds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|k| k.as_str().unwrap())
        .collect();
    assert_eq!(
        kinds,
        [
            "plane", "box", "conveyor", "chute", "trough", "bin", "bin", "bin", "bin", "bin",
            "mesh"
        ]
    );
    assert!(
        !v["notes"].to_string().contains("not drawn"),
        "{}",
        v["notes"]
    );
    s.eval("(() => { const e = document.getElementById('slider'); e.focus(); return 'true'; })()");
    s.tab.press_key("End").unwrap();
    check_positions(&s, &samples, &names);
    let (px, _, _) = s.screenshot();
    assert!(changed_pixels(&px, &vec![px[0]; px.len()]) > 0);

    // With force histories, a contact over a bruise threshold has its force curve: click the
    // apple, then the contact's row.
    let target = s.eval(
        "(() => { const V = applesimView, p = new V.THREE.Vector3(); \
           const c = V.renderer.domElement.getBoundingClientRect(); \
           const ks = Object.keys(V.data.curves).map(Number); \
           for (const k of ks) { const i = V.data.contacts[k].a; \
             p.fromArray(V.apples.userData.at(i)).project(V.camera); \
             const x = c.left + (p.x + 1) / 2 * c.width, y = c.top + (1 - p.y) / 2 * c.height; \
             if (document.elementFromPoint(x, y) === V.renderer.domElement) return JSON.stringify([k, i, x, y, ks.length]); } \
           return JSON.stringify(null); })()",
    );
    assert!(!target.is_null(), "no contact with a force curve on screen");
    assert!(target[4].as_u64().unwrap() >= 1);
    let k = target[0].as_u64().unwrap();
    s.click(target[2].as_f64().unwrap(), target[3].as_f64().unwrap());
    let row = s.eval(&format!(
        "JSON.stringify((r => r ? (r.scrollIntoView({{ block: 'nearest' }}), [r.getBoundingClientRect().left + 20, r.getBoundingClientRect().top + 5]) : null)(document.querySelector('#info tr[data-contact=\"{k}\"]')))"
    ));
    assert!(
        !row.is_null(),
        "the clicked apple's panel has no row for contact {k}"
    );
    s.click(row[0].as_f64().unwrap(), row[1].as_f64().unwrap());
    let svg =
        s.eval("JSON.stringify(document.querySelectorAll('#info svg.curve polyline').length)");
    assert_eq!(svg, 1, "no force curve after clicking contact {k}'s row");
    // APPLESIM_VIEW_SHOTS=DIR keeps a picture of this state (to look at, not checked).
    if let Some(dir) = std::env::var_os("APPLESIM_VIEW_SHOTS") {
        let png_bytes = s
            .tab
            .capture_screenshot(CaptureScreenshotFormatOption::Png, None, None, true)
            .unwrap();
        std::fs::write(Path::new(&dir).join("kinds_curve.png"), png_bytes).unwrap();
    }

    s.open(&empty_dir.join("view.html"), "");
    let v = s.eval(
        "JSON.stringify({ apples: applesimView.apples.userData.count, surfaces: applesimView.surfaces.length, \
           notes: document.getElementById('notes-list').textContent })",
    );
    assert_eq!(v["apples"], 0);
    assert_eq!(v["surfaces"], 11);
    assert!(
        v["notes"]
            .as_str()
            .unwrap()
            .contains("bodies.csv holds no sample"),
        "{}",
        v["notes"]
    );
    let (px, w, h) = s.screenshot();
    let drawn = drawn_pixels(&px);
    assert!(
        drawn > (w * h / 50) as usize,
        "the empty run's page is blank"
    );

    let errors = s.errors();
    assert!(errors.is_empty(), "the pages reported errors: {errors:?}");
}

/// A moving part is drawn where its motion has it at each frame: a box lowered by translation
/// keyframes is carried, in the page's scene, by the prescribed offset at the slider's frame's
/// time (within f32 rounding), with its edges; the fixed floor stays put.
#[test]
fn a_moving_box_follows_its_motion() {
    let dir = tmp("moving");
    // Keyframes: 0.2 m up at t = 0 (the body starts there), down to 0 and 0.1 m along x at
    // 0.3 s, held after. The page's frames are samples every 0.01 s, thinned to 21.
    let keys = [(0.0, [0.0, 0.0, 0.2]), (0.3, [0.1, 0.0, 0.0])];
    let offset = |t: f64| -> [f64; 3] {
        let a = (t / 0.3).clamp(0.0, 1.0);
        [0, 1, 2].map(|k| keys[0].1[k] + a * (keys[1].1[k] - keys[0].1[k]))
    };
    let scenario = serde_json::json!({
        "duration_s": 0.4,
        "time_step_s": 2e-5,
        "gravity_m_s2": [0, 0, -9.81],
        "output": { "sample_interval_s": 0.01 },
        "materials": {
            "apple": { "shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800 },
            "steel": { "youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.28 }
        },
        "contact": { "friction": 0.3, "ke": 0.09, "lambda_s_m": 1000 },
        "apples": [
            { "name": "a", "material": "apple", "diameter_m": 0.08, "position_m": [0, 0, 0.45] },
            { "name": "b", "material": "apple", "diameter_m": 0.07, "position_m": [0.5, 0, 0.1] }
        ],
        "surfaces": [
            { "name": "floor", "type": "plane", "material": "steel", "point_m": [0, 0, 0], "normal": [0, 0, 1] },
            { "name": "lift", "type": "box", "material": "steel", "size_m": [0.3, 0.3, 0.05], "position_m": [0, 0, 0.1],
              "motion": { "translation": { "keyframes": [[keys[0].0, keys[0].1], [keys[1].0, keys[1].1]] } } }
        ]
    });
    let run_dir = run_scenario(&dir, "moving", "run", &scenario, &[]);
    run(&["view", run_dir.to_str().unwrap(), "--max-frames", "21"]);

    let s = launch("moving");
    s.open(&run_dir.join("view.html"), "");
    let notes = s.eval(
        "JSON.stringify([...document.querySelectorAll('#notes-list li')].map(l => l.textContent))",
    );
    assert!(!notes.to_string().contains("where it starts"), "{notes}");
    assert!(
        notes.to_string().contains("moving surface(s) 'lift'"),
        "{notes}"
    );
    // Slider to frame k (as a person's input does), then the meshes' poses.
    let at = |k: usize| {
        s.eval(&format!(
            "(() => {{ const V = applesimView, e = document.getElementById('slider'); \
               e.value = '{k}'; e.dispatchEvent(new Event('input')); \
               const m = V.surfaces.map(x => [x.userData.surface, x.position.toArray(), x.quaternion.toArray(), \
                 x.children.filter(c => c.type === 'LineSegments').length]); \
               return JSON.stringify({{ t: String(V.frameTimes[{k}]), frames: V.frameTimes.length, m }}); }})()"
        ))
    };
    let mut worst = 0.0f64;
    let mut seen = Vec::new();
    for k in [4usize, 10, 20] {
        let v = at(k);
        assert_eq!(v["frames"], 21);
        let t: f64 = v["t"].as_str().unwrap().parse().unwrap();
        let want = offset(t);
        let m = v["m"].as_array().unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m[0][0], "floor");
        assert_eq!(m[1][0], "lift");
        for (name, mesh, moved) in [("floor", &m[0], [0.0; 3]), ("lift", &m[1], want)] {
            for a in 0..3 {
                let got = mesh[1][a].as_f64().unwrap();
                let err = (got - moved[a]).abs();
                worst = worst.max(err);
                // The poses are embedded as f32: one f32 epsilon of the offset.
                assert!(
                    err <= f32::EPSILON as f64 * moved[a].abs(),
                    "{name} at t = {t} s, axis {a}: drawn offset {got} m, prescribed {} m",
                    moved[a]
                );
            }
            assert_eq!(mesh[2], serde_json::json!([0, 0, 0, 1]), "{name} turned");
            assert_eq!(mesh[3], 1, "{name}'s edges are not its child");
        }
        seen.push((t, want));
    }
    // Two distinct poses were checked, the box between its keyframes and past the last.
    assert!(
        seen[0].0 > 0.0 && seen[0].0 < 0.3 && seen[2].0 > 0.3,
        "{seen:?}"
    );
    assert!((seen[0].1[2] - seen[2].1[2]).abs() > 0.1);
    // Colour by impact still works on the moving box: grey at t = 0, coloured once apple a
    // has landed on it (contacts.csv has that contact).
    let contacts = std::fs::read_to_string(run_dir.join("contacts.csv")).unwrap();
    assert!(contacts.lines().any(|l| l.contains(",lift,")), "{contacts}");
    let colour = |k: usize| {
        at(k);
        // A box is see-through: its outline carries its impact colour.
        s.eval("JSON.stringify((m => (m.userData.seeThrough ? m.userData.edges.material.color : m.material.color).getHex())(applesimView.surfaces[1]))")
    };
    assert_ne!(
        colour(0),
        colour(20),
        "the moving box's colour did not change with its impact"
    );
    eprintln!("moving box: worst drawn offset error {worst:.2e} m over frames {seen:?}");
    // docs/viewer.md: the f32 rounding of the offset, measured 5.8e-9 m at most (checked at
    // twice that; Float32Array rounding, the same in any browser).
    assert!(worst <= 2.0 * 5.8e-9, "worst offset error {worst:e} m");
    let errors = s.errors();
    assert!(errors.is_empty(), "the page reported errors: {errors:?}");
}

/// The rotation quaternion [x, y, z, w] of `angle` (rad) about the unit `axis`.
fn quat(axis: [f64; 3], angle: f64) -> [f64; 4] {
    let s = (angle / 2.0).sin();
    [axis[0] * s, axis[1] * s, axis[2] * s, (angle / 2.0).cos()]
}

/// The angle (rad) of the rotation that takes the unit quaternion `a` to `b` (either sign):
/// 2 atan2(|v|, |w|) of a^-1 b, well conditioned near 0 (unlike acos of the dot product).
fn quat_angle(a: [f64; 4], b: [f64; 4]) -> f64 {
    let [ax, ay, az, aw] = [-a[0], -a[1], -a[2], a[3]];
    let [bx, by, bz, bw] = b;
    let x = aw * bx + ax * bw + ay * bz - az * by;
    let y = aw * by - ax * bz + ay * bw + az * bx;
    let z = aw * bz + ax * by - ay * bx + az * bw;
    let w = aw * bw - ax * bx - ay * by - az * bz;
    2.0 * (x * x + y * y + z * z).sqrt().atan2(w.abs())
}

/// `v` turned by the unit quaternion `q`.
fn quat_rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let (u, w) = ([q[0], q[1], q[2]], q[3]);
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let t = cross(u, v).map(|x| 2.0 * x);
    let c = cross(u, t);
    [0, 1, 2].map(|k| v[k] + w * t[k] + c[k])
}

/// The roller tests' axis, (0.6, 0.8, 0) normalised: tilted, so that no component is trivial.
fn roller_axis() -> [f64; 3] {
    let n = 0.6f64.hypot(0.8);
    [0.6 / n, 0.8 / n, 0.0]
}

/// The roller tests' roller centre (m): 0.1 m from the origin, so that turning the roller about
/// the world's origin instead of its own centre would show.
const ROLLER_CENTRE: [f64; 3] = [0.0, 0.0, 0.1];

/// The scene of the roller tests: a floor, one apple resting on it away from the roller, and the
/// roller `roller` (a surface's JSON; radius 25 mm, length 0.3 m, at [`ROLLER_CENTRE`] on
/// [`roller_axis`] are added), sampled every 10 ms for 0.4 s.
fn roller_scenario(mut roller: serde_json::Value) -> serde_json::Value {
    roller["type"] = "roller".into();
    roller["material"] = "steel".into();
    roller["radius_m"] = 0.025.into();
    roller["length_m"] = 0.3.into();
    roller["position_m"] = serde_json::json!(ROLLER_CENTRE);
    roller["axis"] = serde_json::json!([0.6, 0.8, 0]);
    serde_json::json!({
        "duration_s": 0.4,
        "time_step_s": 2e-5,
        "gravity_m_s2": [0, 0, -9.81],
        "output": { "sample_interval_s": 0.01 },
        "materials": {
            "apple": { "shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800 },
            "steel": { "youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.28 }
        },
        "contact": { "friction": 0.3, "ke": 0.09, "lambda_s_m": 1000 },
        "apples": [
            { "name": "a", "material": "apple", "diameter_m": 0.08, "position_m": [0.3, 0, 0.04] }
        ],
        "surfaces": [
            { "name": "floor", "type": "plane", "material": "steel", "point_m": [0, 0, 0], "normal": [0, 0, 1] },
            roller
        ]
    })
}

/// The page's script body returning, as JSON, the drawn pose of the roller `name` (its
/// quaternion `q`, position `p`, the body's rest origin), the apple's position, the page's time
/// `t`, frame count, whether the roller carries stripe colours, and the notes' text.
fn roller_pose_js(name: &str) -> String {
    format!(
        "const m = V.surfaces.find(x => x.userData.surface === '{name}'); \
         const p = V.apples.userData.at(0); \
         return JSON.stringify({{ t: String(V.state.t), q: m.quaternion.toArray(), p: m.position.toArray(), \
           origin: V.data.movers[V.data.surfaces.find(x => x.name === '{name}').mover].origin_m, apple: [p[0], p[1], p[2]], \
           frames: V.frameTimes.length, colours: !!m.geometry.getAttribute('color'), vc: m.material.vertexColors, \
           notes: document.getElementById('notes-list').textContent }});"
    )
}

/// Checks the drawn pose `v` (from [`roller_pose_js`]) against a turn by `angle` (rad) about
/// [`roller_axis`], with the roller's centre where it is: the poses are embedded as f32, each
/// quaternion component rounded to half an f32 epsilon of itself, which turns the rotation by at
/// most one f32 epsilon (1.19e-7 rad); the centre to one f32 epsilon of |c| = 0.1 m. Returns the
/// angle error (rad) and the centre's error (m).
fn check_roller_pose(v: &serde_json::Value, angle: f64) -> (f64, f64) {
    let t = v["t"].as_str().unwrap();
    let q: Vec<f64> = (0..4).map(|k| v["q"][k].as_f64().unwrap()).collect();
    let q = [q[0], q[1], q[2], q[3]];
    let err = quat_angle(quat(roller_axis(), angle), q);
    assert!(
        err <= f32::EPSILON as f64,
        "at t = {t} s the roller is drawn {err:e} rad off its turn {angle} rad: {q:?}"
    );
    // Where the drawn mesh puts the roller's centre: its pose applied to the centre taken
    // relative to the body's origin.
    let origin: Vec<f64> = (0..3).map(|k| v["origin"][k].as_f64().unwrap()).collect();
    let turned = quat_rotate(q, [0, 1, 2].map(|k| ROLLER_CENTRE[k] - origin[k]));
    let mut worst_pos = 0.0f64;
    for a in 0..3 {
        let c = v["p"][a].as_f64().unwrap() + turned[a];
        worst_pos = worst_pos.max((c - ROLLER_CENTRE[a]).abs());
        assert!(
            (c - ROLLER_CENTRE[a]).abs() <= f32::EPSILON as f64 * 0.1,
            "at t = {t} s, axis {a}: the roller's centre drawn at {c} m, not at {} m",
            ROLLER_CENTRE[a]
        );
    }
    (err, worst_pos)
}

/// The turn shows on screen: frames 10 and 11 (`at` moves the slider and returns the pose)
/// differ in more than 100 pixels while the apple, the only other thing that could move, stands
/// still between them. Returns the changed pixels.
fn roller_turn_shows(s: &Session, at: &dyn Fn(usize) -> serde_json::Value) -> usize {
    let a10 = at(10)["apple"].clone();
    let (p10, _, _) = s.screenshot();
    let a11 = at(11)["apple"].clone();
    let (p11, _, _) = s.screenshot();
    for k in 0..3 {
        let d = (a10[k].as_f64().unwrap() - a11[k].as_f64().unwrap()).abs();
        assert!(d < 1e-5, "the apple moved {d} m between frames 10 and 11");
    }
    let changed = changed_pixels(&p10, &p11);
    assert!(
        changed > 100,
        "only {changed} pixels changed as the roller turned"
    );
    changed
}

/// The slider moved to frame `k` (as a person's input does), then `pose_js`'s answer.
fn at_frame(s: &Session, pose_js: &str, k: usize) -> serde_json::Value {
    s.eval(&format!(
        "(() => {{ const V = applesimView, e = document.getElementById('slider'); \
           e.value = '{k}'; e.dispatchEvent(new Event('input')); {pose_js} }})()"
    ))
}

/// A powered roller is drawn turning about its own axis: at 3 slider frames (0.08, 0.2 and
/// 0.4 s, turned 0.8, 2 and 4 rad) and between two frames (t = 0.21 s from the link, the page
/// interpolating), its drawn quaternion is the closed-form turn w t about its (tilted) axis
/// with w = surface speed / radius = 0.25 / 0.025 = 10 rad/s, and the roller's centre stays
/// where it is (between frames too: the page turns it about its centre, not the world's
/// origin); tolerances of [`check_roller_pose`]. Measured: worst angle error 7.5e-8 rad, worst
/// centre error 1.5e-9 m (the f32 rounding of 0.1). It is striped (a colour attribute, half of
/// its side's triangles dark), the page's note says it turns, and the turn shows: the rendered
/// pixels change between two frames while the one apple rests.
#[test]
fn a_powered_roller_turns_at_its_rate() {
    let dir = tmp("roller");
    let w = 0.25 / 0.025;
    let scenario =
        roller_scenario(serde_json::json!({ "name": "drive", "angular_velocity_rad_s": w }));
    let run_dir = run_scenario(&dir, "roller", "run", &scenario, &[]);
    run(&["view", run_dir.to_str().unwrap(), "--max-frames", "21"]);

    let s = launch("roller");
    let pose_js = roller_pose_js("drive");
    let (mut worst_angle, mut worst_pos) = (0.0f64, 0.0f64);
    let mut check = |v: &serde_json::Value, t: f64| {
        let (a, p) = check_roller_pose(v, w * t);
        worst_angle = worst_angle.max(a);
        worst_pos = worst_pos.max(p);
    };
    // Between frames 10 and 11 (0.2 and 0.22 s), from the link.
    s.open(&run_dir.join("view.html"), "#t=0.21");
    let v = s.eval(&format!(
        "(() => {{ const V = applesimView; {pose_js} }})()"
    ));
    assert_eq!(v["frames"], 21);
    assert_eq!(v["t"], "0.21");
    assert_eq!(v["colours"], true, "the roller has no stripes");
    assert_eq!(v["vc"], true);
    let notes = v["notes"].as_str().unwrap();
    assert!(
        notes.contains("roller(s) 'drive' drawn turning about their own axes"),
        "{notes}"
    );
    assert!(!notes.contains("without its turn"), "{notes}");
    check(&v, 0.21);
    // Half the side's triangles (96 of 48 segments) are dark: colour 0.4 on each vertex.
    let dark = s.eval(
        "(() => { const c = applesimView.surfaces.find(x => x.userData.surface === 'drive').geometry.getAttribute('color'); \
           let n = 0; for (let i = 0; i < c.count; i += 3) if (c.getX(i) < 0.5) n++; return JSON.stringify([n, c.count / 3]); })()",
    );
    assert_eq!(dark, serde_json::json!([48, 96 + 92]));
    let at = |k: usize| at_frame(&s, &pose_js, k);
    let mut seen = Vec::new();
    for k in [4usize, 10, 20] {
        let v = at(k);
        let t: f64 = v["t"].as_str().unwrap().parse().unwrap();
        check(&v, t);
        seen.push(t);
    }
    assert_eq!(seen, [0.08, 0.2, 0.4]);
    let changed = roller_turn_shows(&s, &at);
    eprintln!(
        "powered roller: worst angle error {worst_angle:.2e} rad, worst position error {worst_pos:.2e} m, {changed} pixels changed over one frame"
    );
    // docs/viewer.md: measured 7.5e-8 rad (under the f32 epsilon checked above) and 1.5e-9 m, the
    // f32 rounding of 0.1 m (checked at twice that).
    assert!(worst_pos <= 2.0 * 1.5e-9, "centre {worst_pos:e} m");
    let errors = s.errors();
    assert!(errors.is_empty(), "the page reported errors: {errors:?}");
}

/// A free-turning roller is drawn at the angle the run recorded (rollers.csv): the bearing
/// spin-down of tests/rollers.rs (I 2e-4 kg m^2, bearing torque 1e-3 N m, from 10 rad/s, no
/// apple on it), on a tilted axis. At 3 slider frames (0.08, 0.2 and 0.4 s) its drawn
/// quaternion is the turn by rollers.csv's `angle_rad` at that frame's time about its axis (0.78,
/// 1.90 and 3.60 rad, where a powered roller at 10 rad/s would be at 0.8, 2 and 4: the page
/// draws the recorded angle, not w t), and its centre stays put; tolerances of
/// [`check_roller_pose`]. Measured: worst angle error 2.7e-8 rad, worst centre error 1.5e-9 m.
/// The page's note says it turns at the recorded angles, and the turn shows on screen between
/// two frames while the apple rests.
#[test]
fn a_free_roller_turns_at_its_recorded_angle() {
    let dir = tmp("free_roller");
    let scenario = roller_scenario(serde_json::json!({
        "name": "idler", "angular_velocity_rad_s": 10,
        "free_turning": { "moment_of_inertia_kg_m2": 2e-4, "bearing_torque_n_m": 1e-3 }
    }));
    let run_dir = run_scenario(&dir, "free_roller", "run", &scenario, &[]);
    run(&["view", run_dir.to_str().unwrap(), "--max-frames", "21"]);
    // rollers.csv: time_s -> angle_rad.
    let recorded: BTreeMap<String, f64> = csv::Reader::from_path(run_dir.join("rollers.csv"))
        .unwrap()
        .records()
        .map(|r| {
            let r = r.unwrap();
            (r[0].to_string(), r[2].parse().unwrap())
        })
        .collect();

    let s = launch("free_roller");
    let pose_js = roller_pose_js("idler");
    let (mut worst_angle, mut worst_pos) = (0.0f64, 0.0f64);
    s.open(&run_dir.join("view.html"), "");
    let at = |k: usize| at_frame(&s, &pose_js, k);
    let mut seen = Vec::new();
    for k in [4usize, 10, 20] {
        let v = at(k);
        let t = v["t"].as_str().unwrap().to_string();
        let angle = recorded[&t];
        let (a, p) = check_roller_pose(&v, angle);
        worst_angle = worst_angle.max(a);
        worst_pos = worst_pos.max(p);
        seen.push((t, angle));
    }
    let times: Vec<&str> = seen.iter().map(|x| x.0.as_str()).collect();
    assert_eq!(times, ["0.08", "0.2", "0.4"]);
    // The spin-down, not w0 t: 10 x 0.4 - 5 x 0.4^2 / 2 = 3.6 rad at the end.
    assert!((seen[2].1 - 3.6).abs() < 1e-3, "{seen:?}");
    let notes = at(10)["notes"].as_str().unwrap().to_string();
    assert!(
        notes.contains("free-turning roller(s) 'idler' drawn turning about their own axes at the angles rollers.csv recorded"),
        "{notes}"
    );
    assert!(!notes.contains("without its turn"), "{notes}");
    let changed = roller_turn_shows(&s, &at);
    eprintln!(
        "free roller: recorded angles {seen:?}; worst angle error {worst_angle:.2e} rad, worst position error {worst_pos:.2e} m, {changed} pixels changed over one frame"
    );
    // docs/viewer.md: measured 2.7e-8 rad and 1.5e-9 m (checked at twice that).
    assert!(worst_angle <= 2.0 * 2.7e-8, "angle {worst_angle:e} rad");
    assert!(worst_pos <= 2.0 * 1.5e-9, "centre {worst_pos:e} m");
    let errors = s.errors();
    assert!(errors.is_empty(), "the page reported errors: {errors:?}");
}

/// The spheroid test's scene (issue 29), sampled every 10 ms for 0.3 s: on a steel floor an
/// oblate apple (80 x 60 mm) turned 90 degrees about x, lying on its cheek (its axis along -y,
/// its centre a = 40 mm up), an elongated one (60 x 90 mm) turned 30 degrees about x (its axis
/// (0, -1/2, sqrt(3)/2)) dropped from 0.1 m so that it lands, rocks and turns, and a sphere of
/// 70 mm resting, all in a row along y.
fn spheroid_scenario() -> serde_json::Value {
    serde_json::json!({
        "duration_s": 0.3,
        "time_step_s": 1e-5,
        "gravity_m_s2": [0, 0, -9.81],
        "output": { "sample_interval_s": 0.01 },
        "materials": {
            "apple": { "shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800 },
            "steel": { "youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.28 }
        },
        "contact": { "friction": 0.3, "ke": 0.09, "lambda_s_m": 1000 },
        "apples": [
            { "name": "oblate", "material": "apple", "diameter_m": 0.08, "height_m": 0.06,
              "rotation": { "axis": [1, 0, 0], "angle_deg": 90 }, "position_m": [0, 0, 0.04] },
            { "name": "long", "material": "apple", "diameter_m": 0.06, "height_m": 0.09,
              "rotation": { "axis": [1, 0, 0], "angle_deg": 30 }, "position_m": [0, 0.15, 0.1] },
            { "name": "ball", "material": "apple", "diameter_m": 0.07, "position_m": [0, -0.13, 0.035] }
        ],
        "surfaces": [
            { "name": "floor", "type": "plane", "material": "steel", "point_m": [0, 0, 0], "normal": [0, 0, 1] }
        ]
    })
}

/// An apple's row of bodies.csv as the spheroid test reads it: centre (m), diameter and height
/// (m), orientation quaternion [x, y, z, w] (bodies.csv prints w first).
#[derive(Debug, Clone, Copy)]
struct ShapeRow {
    centre: [f64; 3],
    d: f64,
    h: f64,
    q: [f64; 4],
}

/// bodies.csv with its shape columns: per sample time (bits), per apple, its [`ShapeRow`].
fn shape_rows(run_dir: &Path) -> BTreeMap<u64, BTreeMap<String, ShapeRow>> {
    let mut r = csv::Reader::from_path(run_dir.join("bodies.csv")).unwrap();
    let h = r.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    let c = [
        "time_s",
        "x_m",
        "y_m",
        "z_m",
        "diameter_m",
        "height_m",
        "qx",
        "qy",
        "qz",
        "qw",
    ]
    .map(col);
    let ca = col("apple");
    let mut out: BTreeMap<u64, BTreeMap<String, ShapeRow>> = BTreeMap::new();
    for rec in r.records() {
        let rec = rec.unwrap();
        let v = c.map(|k| rec[k].parse::<f64>().unwrap());
        out.entry(v[0].to_bits()).or_default().insert(
            rec[ca].to_string(),
            ShapeRow {
                centre: [v[1], v[2], v[3]],
                d: v[4],
                h: v[5],
                q: [v[6], v[7], v[8], v[9]],
            },
        );
    }
    out
}

/// The unit axis of a spheroid turned by `q` ([x, y, z, w], normalised first): R e_z.
fn axis_of(q: [f64; 4]) -> [f64; 3] {
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    quat_rotate(q.map(|x| x / n), [0.0, 0.0, 1.0])
}

/// The angle (rad) between two axes of a spheroid (either sign: a spheroid turned end over end
/// is the same body).
fn axis_angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    let dot = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]).abs();
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2])
        .sqrt()
        .atan2(dot)
}

/// The page's camera as the test projects with it: eye, right, up, forward (world, unit), the
/// projection's x and y scales (1 / (tan(fov/2) aspect), 1 / tan(fov/2)) and the canvas in device
/// pixels (left, top, width, height).
struct PageCamera {
    eye: [f64; 3],
    right: [f64; 3],
    up: [f64; 3],
    fwd: [f64; 3],
    px: f64,
    py: f64,
    rect: [f64; 4],
}

fn page_camera(s: &Session) -> PageCamera {
    let v = s.eval(
        "(() => { const V = applesimView, c = V.renderer.domElement.getBoundingClientRect(), d = window.devicePixelRatio || 1; \
           V.camera.updateMatrixWorld(); \
           return JSON.stringify({ m: V.camera.matrixWorld.elements, p: V.camera.projectionMatrix.elements, \
             rect: [c.left * d, c.top * d, c.width * d, c.height * d] }); })()",
    );
    let m: Vec<f64> = (0..16).map(|k| v["m"][k].as_f64().unwrap()).collect();
    let p: Vec<f64> = (0..16).map(|k| v["p"][k].as_f64().unwrap()).collect();
    PageCamera {
        eye: [m[12], m[13], m[14]],
        right: [m[0], m[1], m[2]],
        up: [m[4], m[5], m[6]],
        fwd: [-m[8], -m[9], -m[10]],
        px: p[0],
        py: p[5],
        rect: [0, 1, 2, 3].map(|k| v["rect"][k].as_f64().unwrap()),
    }
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The closed form of a spheroid's silhouette seen by the page's perspective camera: its
/// bounding box on the screen (device pixels: left, right, top, bottom). The spheroid of centre
/// c, semi-axes a (across) and h (along the unit axis k) is the ellipsoid of shape matrix
/// S = a^2 I + (h^2 - a^2) k k^T, whose support is |n . (x - c)| <= sqrt(n^T S n). A plane
/// through the eye e on which the screen coordinate X = (s . (x - e)) / (f . (x - e)) is constant
/// (s the screen's right or up, f the view direction) has normal n = s - X f; the silhouette's
/// extreme X are those of the two such planes tangent to the ellipsoid:
/// (s . g - X f . g)^2 = (s - X f)^T S (s - X f), g = c - e, a quadratic in X.
fn silhouette(cam: &PageCamera, c: [f64; 3], a: f64, h: f64, k: [f64; 3]) -> [f64; 4] {
    let g = [0, 1, 2].map(|i| c[i] - cam.eye[i]);
    let sm =
        |x: [f64; 3], y: [f64; 3]| a * a * dot3(x, y) + (h * h - a * a) * dot3(x, k) * dot3(y, k);
    let range = |s: [f64; 3]| {
        let (al, be) = (dot3(s, g), dot3(cam.fwd, g));
        let qa = be * be - sm(cam.fwd, cam.fwd);
        let qb = al * be - sm(s, cam.fwd);
        let qc = al * al - sm(s, s);
        let root = (qb * qb - qa * qc).sqrt();
        ((qb - root) / qa, (qb + root) / qa)
    };
    let [l, t, w, hh] = cam.rect;
    let (x0, x1) = range(cam.right);
    let (y0, y1) = range(cam.up);
    [
        l + (cam.px * x0 + 1.0) / 2.0 * w,
        l + (cam.px * x1 + 1.0) / 2.0 * w,
        t + (1.0 - cam.py * y1) / 2.0 * hh,
        t + (1.0 - cam.py * y0) / 2.0 * hh,
    ]
}

/// Shows the apples alone (the other objects of the scene, the panels and the scale bar hidden) and returns
/// the screenshot's pixels and width.
fn apples_alone(s: &Session) -> (Vec<u8>, u32) {
    s.eval(
        "(() => { const V = applesimView; V.scene.children.forEach((o) => { if (o !== V.apples && !o.isLight) o.visible = false; }); \
           document.querySelectorAll('.panel, #scalebar').forEach((e) => { e.style.visibility = 'hidden'; }); return 'true'; })()",
    );
    let (px, w, _) = s.screenshot();
    (px, w)
}

/// The drawn silhouettes of `names` against their closed forms ([`silhouette`]) at the page's
/// current time, whose bodies.csv rows are `rows`: each apple's pixels (those off the background
/// within 12 px of its closed-form box) span that box within `tol` px on every side, and no
/// pixel is drawn outside them. Returns the largest edge error (px) and each apple's measured
/// half-extents across and up the screen (px).
fn check_silhouettes(
    s: &Session,
    rows: &BTreeMap<String, ShapeRow>,
    names: &[&str],
    tol: f64,
) -> (f64, Vec<(f64, f64)>) {
    let cam = page_camera(s);
    let boxes: Vec<[f64; 4]> = names
        .iter()
        .map(|n| {
            let r = rows[*n];
            silhouette(&cam, r.centre, r.d / 2.0, r.h / 2.0, axis_of(r.q))
        })
        .collect();
    let (px, w) = apples_alone(s);
    let bg = [px[0], px[1], px[2], px[3]];
    let mut spans = vec![
        [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY
        ];
        names.len()
    ];
    let mut stray = 0usize;
    for (k, p) in px.chunks(4).enumerate() {
        if !differs(p, &bg) {
            continue;
        }
        let (x, y) = ((k % w as usize) as f64, (k / w as usize) as f64);
        let owner = boxes.iter().position(|b| {
            x + 1.0 > b[0] - 12.0 && x < b[1] + 12.0 && y + 1.0 > b[2] - 12.0 && y < b[3] + 12.0
        });
        match owner {
            Some(i) => {
                // A pixel covers [x, x + 1): the drawn silhouette reaches its far edge.
                let sp = &mut spans[i];
                sp[0] = sp[0].min(x);
                sp[1] = sp[1].max(x + 1.0);
                sp[2] = sp[2].min(y);
                sp[3] = sp[3].max(y + 1.0);
            }
            None => stray += 1,
        }
    }
    assert_eq!(stray, 0, "pixels drawn outside every apple's silhouette");
    let mut worst = 0.0f64;
    let mut halves = Vec::new();
    for (i, n) in names.iter().enumerate() {
        for e in 0..4 {
            let err = (spans[i][e] - boxes[i][e]).abs();
            worst = worst.max(err);
            assert!(
                err <= tol,
                "{n}: drawn box {:?}, closed form {:?} (edge {e} {err:.2} px off)",
                spans[i],
                boxes[i]
            );
        }
        halves.push((
            (spans[i][1] - spans[i][0]) / 2.0,
            (spans[i][3] - spans[i][2]) / 2.0,
        ));
    }
    s.eval(
        "(() => { applesimView.scene.children.forEach((o) => { o.visible = true; }); \
           document.querySelectorAll('.panel, #scalebar').forEach((e) => { e.style.visibility = ''; }); return 'true'; })()",
    );
    (worst, halves)
}

/// Spheroidal apples (issue 29) are drawn as the ellipsoids of their diameter and height, turned
/// by their orientation at every frame. The scene of [`spheroid_scenario`] seen from the side
/// (the camera 0.5 m away along -x, so that the screen's right is -y and its up z):
/// - at every frame (31) each apple is drawn with its radius D/2, its polar semi-axis H/2 and
///   its axis R(q) e_z from bodies.csv's quaternion at that frame's time (the page's i16
///   quaternions: within 1e-4 rad; measured below), and between two frames (t = 0.105 s, from
///   the link) along the slerp of the two frames' quaternions halfway;
/// - at t = 0, where the orientations are the scenario's turns (bodies.csv's quaternions are
///   (cos 45, sin 45, 0, 0) and (cos 15, sin 15, 0, 0) within 1e-9), and at the end, after the
///   elongated apple has landed and turned, the silhouette of each apple on the screen (the
///   apples shown alone) spans the closed-form silhouette of its ellipsoid under the page's
///   perspective camera ([`silhouette`]) within 1 px on every side, nothing drawn outside them:
///   the oblate apple on its cheek shows about c = 30 mm across and a = 40 mm up (perspective
///   adds about 0.3 %), the elongated one a tilted outline, the sphere a disc;
/// - hovering inside the oblate apple's outline along its axis (0.9 of its half-extent there)
///   names it ("oblate (80 x 60 mm, ..."), outside it (1.15, still inside its 40 mm radius
///   across) names none: picking follows the drawn shape.
#[test]
fn spheroids_are_drawn_as_their_ellipsoids() {
    let dir = tmp("spheroids");
    let run_dir = run_scenario(&dir, "spheroids", "run", &spheroid_scenario(), &["--view"]);
    let rows = shape_rows(&run_dir);
    let times: Vec<f64> = rows.keys().map(|b| f64::from_bits(*b)).collect();
    assert_eq!(times.len(), 31);
    let names = ["oblate", "long", "ball"];
    let at0 = &rows[&0f64.to_bits()];
    let (s45, c45) = (0.25 * std::f64::consts::PI).sin_cos();
    let (s15, c15) = (std::f64::consts::PI / 12.0).sin_cos();
    for (n, want) in [
        ("oblate", [s45, 0.0, 0.0, c45]),
        ("long", [s15, 0.0, 0.0, c15]),
        ("ball", [0.0, 0.0, 0.0, 1.0]),
    ] {
        for k in 0..4 {
            assert!(
                (at0[n].q[k] - want[k]).abs() < 1e-9,
                "{n} starts at {:?}, not {want:?}",
                at0[n].q
            );
        }
    }

    let s = launch("spheroids");
    // From the side: the camera 0.5 m along -x from the middle of the row, slightly above.
    s.open(
        &run_dir.join("view.html"),
        "#t=0&cam=-0.5,0.01,0.07,0,0.01,0.05",
    );

    // Every frame: the drawn shape is bodies.csv's.
    let drawn = s.eval(
        "(() => { const V = applesimView, e = document.getElementById('slider'), out = []; \
           for (let k = 0; k < V.frameTimes.length; k++) { e.value = String(k); e.dispatchEvent(new Event('input')); \
             const f = [String(V.state.t)]; for (let i = 0; i < V.apples.userData.count; i++) f.push([...V.apples.userData.at(i), ...V.apples.userData.shapeAt(i)]); \
             out.push(f); } \
           return JSON.stringify({ names: V.data.apples.map((a) => a.name), frames: out }); })()",
    );
    let page_names: Vec<&str> = drawn["names"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    assert_eq!(page_names, names);
    let frames = drawn["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 31);
    let mut worst_axis = 0.0f64;
    let check_shape = |row: &ShapeRow, v: &serde_json::Value, axis: [f64; 3], what: &str| {
        let g = |k: usize| v[k].as_f64().unwrap();
        let f32_tol = |x: f64| x * f32::EPSILON as f64;
        assert!(
            (g(3) - row.d / 2.0).abs() <= f32_tol(row.d),
            "{what}: radius {}",
            g(3)
        );
        assert!(
            (g(4) - row.h / 2.0).abs() <= f32_tol(row.h),
            "{what}: polar {}",
            g(4)
        );
        let err = axis_angle([g(5), g(6), g(7)], axis);
        assert!(err < 1e-4, "{what}: axis {err:e} rad off");
        err
    };
    for f in frames {
        let f = f.as_array().unwrap();
        let t: f64 = f[0].as_str().unwrap().parse().unwrap();
        let at = &rows[&t.to_bits()];
        for (i, n) in names.iter().enumerate() {
            let err = check_shape(
                &at[*n],
                &f[i + 1],
                axis_of(at[*n].q),
                &format!("{n} at t = {t}"),
            );
            worst_axis = worst_axis.max(err);
        }
    }
    // The elongated apple turns over the run (it lands tilted): the check is not of one pose.
    let turned = axis_angle(
        axis_of(at0["long"].q),
        axis_of(rows[&0.3f64.to_bits()]["long"].q),
    );
    assert!(turned > 0.1, "the elongated apple turned only {turned} rad");

    // Between two frames, from the link: halfway along the slerp of their quaternions.
    s.open(
        &run_dir.join("view.html"),
        "#t=0.105&cam=-0.5,0.01,0.07,0,0.01,0.05",
    );
    let mid = s.eval(
        "(() => { const V = applesimView, out = [String(V.state.t)]; \
           for (let i = 0; i < V.apples.userData.count; i++) out.push([...V.apples.userData.at(i), ...V.apples.userData.shapeAt(i)]); \
           return JSON.stringify(out); })()",
    );
    assert_eq!(mid[0], "0.105");
    let (r0, r1) = (&rows[&0.1f64.to_bits()], &rows[&0.11f64.to_bits()]);
    for (i, n) in names.iter().enumerate() {
        let q = slerp(r0[*n].q, r1[*n].q, 0.5);
        let err = check_shape(
            &r0[*n],
            &mid[i + 1],
            axis_of(q),
            &format!("{n} at t = 0.105"),
        );
        worst_axis = worst_axis.max(err);
    }

    // The silhouettes at the start and at the end.
    s.open(
        &run_dir.join("view.html"),
        "#t=0&cam=-0.5,0.01,0.07,0,0.01,0.05",
    );
    let (w0, halves) = check_silhouettes(&s, at0, &names, 1.0);
    // Picking follows the outline: along the oblate apple's axis (the screen's x).
    let cam = page_camera(&s);
    let r = at0["oblate"];
    let b = silhouette(&cam, r.centre, r.d / 2.0, r.h / 2.0, axis_of(r.q));
    let dpr = s
        .eval("JSON.stringify(window.devicePixelRatio || 1)")
        .as_f64()
        .unwrap();
    let (cx, cy, half) = (
        (b[0] + b[1]) / 2.0,
        (b[2] + b[3]) / 2.0,
        (b[1] - b[0]) / 2.0,
    );
    for (f, over) in [(0.9, true), (1.15, false)] {
        s.tab
            .move_mouse_to_point(Point {
                x: (cx + f * half) / dpr,
                y: cy / dpr,
            })
            .unwrap();
        let tip = s.eval(
            "JSON.stringify([document.getElementById('tip').style.display, document.getElementById('tip').textContent])",
        );
        let named =
            tip[0] == "block" && tip[1].as_str().unwrap().starts_with("oblate (80 x 60 mm, ");
        assert_eq!(
            named, over,
            "hover at {f} of the oblate apple's half-width: {tip}"
        );
        if !over {
            assert_ne!(tip[0], "block", "hover outside every apple: {tip}");
        }
    }
    s.open(
        &run_dir.join("view.html"),
        "#t=0.3&cam=-0.5,0.01,0.07,0,0.01,0.05",
    );
    let (w1, halves_end) = check_silhouettes(&s, &rows[&0.3f64.to_bits()], &names, 1.0);
    eprintln!(
        "spheroids: axis within {worst_axis:.2e} rad of bodies.csv at every frame and between; \
         silhouettes within {w0:.2} px (t = 0) and {w1:.2} px (t = 0.3 s) of the closed form; \
         half-extents across x up (px) at t = 0 {halves:?}, at the end {halves_end:?}; \
         scale {:.1} px per mm at the oblate apple",
        cam.px * cam.rect[2] / 2.0 / (r.centre[0] - cam.eye[0]) / 1000.0
    );
    let errors = s.errors();
    assert!(errors.is_empty(), "the page reported errors: {errors:?}");
}

/// The slerp of unit quaternions [x, y, z, w] (normalised first) at `t`, the shorter way round.
fn slerp(a: [f64; 4], b: [f64; 4], t: f64) -> [f64; 4] {
    let n = |q: [f64; 4]| {
        let l = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        q.map(|x| x / l)
    };
    let (a, mut b) = (n(a), n(b));
    let mut d: f64 = (0..4).map(|k| a[k] * b[k]).sum();
    if d < 0.0 {
        b = b.map(|x| -x);
        d = -d;
    }
    let th = d.min(1.0).acos();
    if th < 1e-12 {
        return a;
    }
    let (wa, wb) = (((1.0 - t) * th).sin() / th.sin(), (t * th).sin() / th.sin());
    n([0, 1, 2, 3].map(|k| wa * a[k] + wb * b[k]))
}
