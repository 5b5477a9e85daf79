//! What the viewer's browser tests share (tests/view_browser.rs, tests/view_answers.rs): a
//! headless Chromium session with a fresh profile that collects the page's errors, opening a
//! page and waiting for its first frame, evaluating script, screenshots decoded to pixels, runs
//! of applesim, and bodies.csv read back to check the drawn positions.

#![allow(dead_code)]

use headless_chrome::browser::tab::point::Point;
use headless_chrome::protocol::cdp::types::Event;
use headless_chrome::protocol::cdp::Page::CaptureScreenshotFormatOption;
use headless_chrome::protocol::cdp::{Log, Runtime};
use headless_chrome::{Browser, Tab};
#[path = "../chromium_launch/mod.rs"]
mod chromium_launch;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

pub const WIDTH: u32 = 1280;
pub const HEIGHT: u32 = 800;

pub fn exe() -> &'static str {
    env!("CARGO_BIN_EXE_applesim")
}

pub fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("view_browser")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A headless Chromium with a fresh profile, and the errors its pages report.
pub struct Session {
    pub _browser: Browser,
    pub tab: Arc<Tab>,
    pub errors: Arc<Mutex<Vec<String>>>,
    pub _profile: PathBuf,
}

pub fn launch(name: &str) -> Session {
    let profile = tmp(&format!("profile-{name}"));
    let browser = chromium_launch::start(&profile, WIDTH, HEIGHT, Duration::from_secs(120));
    let tab = browser.new_tab().unwrap();
    tab.set_default_timeout(Duration::from_secs(60));
    let errors = Arc::new(Mutex::new(Vec::new()));
    let sink = errors.clone();
    tab.add_event_listener(Arc::new(move |event: &Event| {
        let msg = match event {
            Event::RuntimeConsoleAPICalled(e)
                if e.params.Type == Runtime::ConsoleAPICalledEventTypeOption::Error =>
            {
                Some(format!(
                    "console.error: {}",
                    e.params
                        .args
                        .iter()
                        .map(|a| a
                            .value
                            .as_ref()
                            .map(|v| v.to_string())
                            .or(a.description.clone())
                            .unwrap_or_default())
                        .collect::<Vec<_>>()
                        .join(" ")
                ))
            }
            Event::RuntimeExceptionThrown(e) => Some(format!(
                "exception: {} {}",
                e.params.exception_details.text,
                e.params
                    .exception_details
                    .exception
                    .as_ref()
                    .and_then(|x| x.description.clone())
                    .unwrap_or_default()
            )),
            Event::LogEntryAdded(e) if e.params.entry.level == Log::LogEntryLevel::Error => {
                Some(format!("log error: {}", e.params.entry.text))
            }
            _ => None,
        };
        if let Some(m) = msg {
            sink.lock().unwrap().push(m);
        }
    }))
    .unwrap();
    tab.enable_runtime().unwrap();
    tab.enable_log().unwrap();
    Session {
        _browser: browser,
        tab,
        errors,
        _profile: profile,
    }
}

impl Session {
    /// Opens `page` (a file on disk) with the link's `hash` and waits until the viewer has
    /// drawn its first frame. The page is loaded afresh (from a blank page: a link to the page
    /// already open that differs only in its hash would not load it again), and it is known by
    /// its path, not its whole address: the page writes the view into the address's hash.
    pub fn open(&self, page: &Path, hash: &str) -> Duration {
        let path = page.canonicalize().unwrap().display().to_string();
        let url = format!("file://{path}{hash}");
        self.tab.navigate_to("about:blank").unwrap();
        self.tab.wait_until_navigated().unwrap();
        let t0 = Instant::now();
        let marker = path.clone();
        self.tab.navigate_to(&url).unwrap();
        // Polled rather than waiting for the load event: the page is ready when its scene is
        // drawn (or it says why not), which comes after the load anyway.
        loop {
            let ready = self
                .tab
                .evaluate(
                    &format!(
                        "JSON.stringify(decodeURIComponent(location.pathname) !== {marker:?} ? false : \
                         !!(window.applesimView && window.applesimView.ready) || \
                         (document.getElementById('fatal') && document.getElementById('fatal').style.display === 'block' ? \
                         document.getElementById('fatal').textContent : false))"
                    ),
                    false,
                )
                .ok()
                .and_then(|r| r.value)
                .and_then(|v| v.as_str().map(|s| serde_json::from_str(s).unwrap()))
                .unwrap_or(serde_json::Value::Bool(false));
            match ready {
                serde_json::Value::Bool(true) => break,
                serde_json::Value::String(s) => panic!("the page failed: {s}"),
                _ => {}
            }
            assert!(
                t0.elapsed() < Duration::from_secs(60),
                "the page did not start in 60 s; errors: {:?}",
                self.errors()
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        t0.elapsed()
    }

    /// Evaluates `js`, which must yield a JSON string.
    pub fn eval(&self, js: &str) -> serde_json::Value {
        let r = self.tab.evaluate(js, true).unwrap();
        let s = r
            .value
            .unwrap_or_else(|| panic!("no value from {js}: {:?}", r.description));
        serde_json::from_str(s.as_str().expect("a JSON string")).unwrap()
    }

    pub fn errors(&self) -> Vec<String> {
        self.errors.lock().unwrap().clone()
    }

    /// A screenshot after two more animation frames (the page draws on requestAnimationFrame).
    pub fn screenshot(&self) -> (Vec<u8>, u32, u32) {
        self.eval(
            "new Promise(r => requestAnimationFrame(() => requestAnimationFrame(() => r('true'))))",
        );
        let png_bytes = self
            .tab
            .capture_screenshot(CaptureScreenshotFormatOption::Png, None, None, true)
            .unwrap();
        decode(&png_bytes)
    }

    pub fn click(&self, x: f64, y: f64) {
        self.tab.click_point(Point { x, y }).unwrap();
    }
}

/// RGBA pixels of a PNG.
pub fn decode(bytes: &[u8]) -> (Vec<u8>, u32, u32) {
    let mut d = png::Decoder::new(bytes);
    d.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut r = d.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size()];
    let info = r.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    let rgba: Vec<u8> = match info.color_type {
        png::ColorType::Rgba => buf,
        png::ColorType::Rgb => buf
            .chunks(3)
            .flat_map(|c| [c[0], c[1], c[2], 255])
            .collect(),
        other => panic!("unexpected PNG colour type {other:?}"),
    };
    (rgba, info.width, info.height)
}

/// Whether two RGBA pixels differ by more than 24 (sum over the colour channels).
pub fn differs(p: &[u8], q: &[u8]) -> bool {
    (0..3)
        .map(|k| (p[k] as i32 - q[k] as i32).abs())
        .sum::<i32>()
        > 24
}

/// Pixels whose colour differs between two screenshots.
pub fn changed_pixels(a: &[u8], b: &[u8]) -> usize {
    a.chunks(4)
        .zip(b.chunks(4))
        .filter(|(p, q)| differs(p, q))
        .count()
}

/// Pixels of a screenshot not of its background (the colour of its first pixel).
pub fn drawn_pixels(px: &[u8]) -> usize {
    px.chunks(4).filter(|p| differs(p, &px[..4])).count()
}

pub fn run(args: &[&str]) -> std::process::Output {
    let o = Command::new(exe()).args(args).output().unwrap();
    assert!(
        o.status.success(),
        "applesim {args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// Writes `scenario` to `dir/NAME.json` and runs it into `dir/OUT` with `extra` arguments;
/// returns the run folder.
pub fn run_scenario(
    dir: &Path,
    name: &str,
    out: &str,
    scenario: &serde_json::Value,
    extra: &[&str],
) -> PathBuf {
    let sc_path = dir.join(format!("{name}.json"));
    std::fs::write(&sc_path, serde_json::to_string_pretty(scenario).unwrap()).unwrap();
    let run_dir = dir.join(out);
    let mut args = vec![
        "run",
        sc_path.to_str().unwrap(),
        "--out",
        run_dir.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    run(&args);
    run_dir
}

/// bodies.csv as the test reads it: per sample time, per apple name, the centre.
pub type Samples = BTreeMap<u64, BTreeMap<String, [f64; 3]>>;

pub fn bodies(run_dir: &Path) -> (Samples, Vec<String>) {
    let mut r = csv::Reader::from_path(run_dir.join("bodies.csv")).unwrap();
    let h = r.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    let (ct, ca, cx, cy, cz) = (
        col("time_s"),
        col("apple"),
        col("x_m"),
        col("y_m"),
        col("z_m"),
    );
    let mut out = Samples::new();
    let mut names = Vec::new();
    for rec in r.records() {
        let rec = rec.unwrap();
        let t: f64 = rec[ct].parse().unwrap();
        if !names.iter().any(|n| n == &rec[ca]) {
            names.push(rec[ca].to_string());
        }
        let p = [cx, cy, cz].map(|c| rec[c].parse::<f64>().unwrap());
        out.entry(t.to_bits())
            .or_default()
            .insert(rec[ca].to_string(), p);
    }
    (out, names)
}

/// Surface parts of a run's scenario: a bin is its floor and four walls.
pub fn surface_parts(run_dir: &Path) -> usize {
    let sc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run_dir.join("scenario.json")).unwrap())
            .unwrap();
    sc["surfaces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| if s["type"] == "bin" { 5 } else { 1 })
        .sum()
}

/// Checks that every apple drawn at the slider's current frame stands where bodies.csv has it
/// at that frame's time, within the page's quantisation step (plus f32 rounding); returns the
/// frame's time.
pub fn check_positions(s: &Session, samples: &Samples, names: &[String]) -> f64 {
    let v = s.eval(
        "(() => { const V = window.applesimView; \
           const k = parseInt(document.getElementById('slider').value, 10); \
           const out = []; for (let i = 0; i < V.apples.userData.count; i++) { \
           out.push([V.data.apples[i].name, ...V.apples.userData.at(i)]); } \
           return JSON.stringify({ frame: k, t: String(V.frameTimes[k]), step: V.data.position_step_m, apples: out }); })()",
    );
    // As text: serde_json's default float parsing may be one unit in the last place off, Rust's
    // own is exact (and JavaScript prints the shortest text that reads back exactly).
    let t: f64 = v["t"].as_str().unwrap().parse().unwrap();
    let at = samples
        .get(&t.to_bits())
        .unwrap_or_else(|| panic!("the slider's time {t} s is not a sample time of bodies.csv"));
    let step: Vec<f64> = v["step"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let drawn = v["apples"].as_array().unwrap();
    assert_eq!(drawn.len(), names.len());
    let mut checked = 0;
    for a in drawn {
        let name = a[0].as_str().unwrap();
        let scale = a[4].as_f64().unwrap();
        match at.get(name) {
            Some(p) => {
                assert!(
                    scale > 0.0,
                    "{name} is in bodies.csv at t = {t} s but hidden"
                );
                for k in 0..3 {
                    let got = a[k + 1].as_f64().unwrap();
                    let tol = step[k] / 2.0 + 1e-6 * (1.0 + p[k].abs());
                    assert!(
                        (got - p[k]).abs() <= tol,
                        "{name} at t = {t} s, axis {k}: page {got}, bodies.csv {} (step {})",
                        p[k],
                        step[k]
                    );
                }
                checked += 1;
            }
            None => assert_eq!(
                scale, 0.0,
                "{name} is not in bodies.csv at t = {t} s but drawn"
            ),
        }
    }
    assert_eq!(checked, at.len());
    t
}
