//! The pictures of docs/viewer.md, made from shipped scenarios in headless Chromium (the browser
//! the viewer's tests use), so that they are remade, not drawn by hand:
//!
//! ```sh
//! cargo build --release
//! cargo run --release --example view_pictures -- docs/viewer
//! ```
//!
//! Each scenario is run with `applesim run ... --view` (the `applesim` binary beside this
//! example's folder, `target/release/applesim`) into a temporary folder; each picture is the
//! page opened at a link (`view.html#t=...&colour=...`, the link that follows the view) in a
//! 1280 x 800 window, captured once the page has drawn it. `--no-line-200` leaves out the
//! 200-apple line (a 17 s run).

#[path = "../tests/chromium_launch/mod.rs"]
mod chromium_launch;

use headless_chrome::protocol::cdp::Page::CaptureScreenshotFormatOption;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// A picture: its file name, the run's folder name, the link's hash, what it shows.
struct Picture {
    file: &'static str,
    run: &'static str,
    hash: &'static str,
    what: &'static str,
}

/// The runs: folder name, scenario, whether it is the long 200-apple line.
const RUNS: [(&str, &str, bool); 5] = [
    ("drop", "scenarios/drop_on_steel.json", false),
    ("spheroids", "docs/viewer/spheroids.json", false),
    ("line", "scenarios/handling_line.json", false),
    ("bin_filler", "scenarios/lines/bin_filler.json", false),
    ("line_200", "scenarios/bench/view_line_200.json", true),
];

const PICTURES: [Picture; 9] = [
    Picture {
        file: "drop_on_steel.png",
        run: "drop",
        hash: "#t=0.00289&colour=g",
        what: "the drop on steel at its peak force, coloured by peak g",
    },
    Picture {
        file: "handling_line_grade.png",
        run: "line",
        hash: "#t=10&colour=grade",
        what: "the handling line at the end, coloured by grade, the audit table on the left",
    },
    Picture {
        file: "handling_line_volume.png",
        run: "line",
        hash: "#t=6&colour=volume&pick=feed-3",
        what:
            "the handling line at 6 s, coloured by bruise volume so far, feed-3 picked: its history",
    },
    Picture {
        file: "handling_line_audit.png",
        run: "line",
        hash: "#t=10&colour=volume&part=apples%20in%20bin&cam=1.3,-0.75,0.55,1.85,0,0.08",
        what:
            "the audit's row 'apples in bin' picked: the bin highlighted, only its contacts marked",
    },
    Picture {
        file: "handling_line_bruises.png",
        run: "line",
        hash: "#t=10&colour=grade&cam=1.5,-0.5,0.6,1.85,0,0.05",
        what: "the bin close up: bruises on the apples' skins, sized by their area",
    },
    Picture {
        file: "bin_filler_motion.png",
        run: "bin_filler",
        hash: "#t=12&colour=motion",
        what: "the bin filler at 12 s, coloured by motion, seen through the bin's walls",
    },
    Picture {
        file: "handling_line_trails.png",
        run: "line",
        hash: "#t=4.5&colour=speed&trails=2",
        what: "the handling line at 4.5 s, coloured by speed, with 2 s trails",
    },
    Picture {
        file: "spheroids.png",
        run: "spheroids",
        hash: "#t=0.79&colour=force&cam=0.5,-0.78,0.62,0.0,0.02,0",
        what: "24 spheroidal apples (height over diameter 0.7 to 1.1, turned at random) in a bin",
    },
    Picture {
        file: "view_line_volume.png",
        run: "line_200",
        hash: "#t=22&colour=volume",
        what: "the 200-apple line at 22 s, coloured by bruise volume so far",
    },
];

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(out) = args
        .iter()
        .find(|a| !a.starts_with("--"))
        .map(PathBuf::from)
    else {
        eprintln!("usage: view_pictures OUT_DIR [--no-line-200]");
        std::process::exit(2);
    };
    let long = !args.iter().any(|a| a == "--no-line-200");
    std::fs::create_dir_all(&out).unwrap();
    let exe = std::env::current_exe().unwrap();
    let applesim = exe
        .parent()
        .and_then(Path::parent)
        .map(|d| d.join("applesim"))
        .filter(|p| p.is_file())
        .unwrap_or_else(|| {
            eprintln!(
                "no target/release/applesim beside this example: run `cargo build --release` first"
            );
            std::process::exit(2);
        });
    let work = std::env::temp_dir().join(format!("applesim-view-pictures-{}", std::process::id()));
    std::fs::create_dir_all(&work).unwrap();
    for (name, scenario, is_long) in RUNS {
        if is_long && !long {
            continue;
        }
        let t0 = Instant::now();
        let o = Command::new(&applesim)
            .args(["run", scenario, "--view", "-q", "--out"])
            .arg(work.join(name))
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "applesim run {scenario}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        eprintln!("ran {scenario} in {:.1} s", t0.elapsed().as_secs_f64());
    }
    let profile = work.join("profile");
    let browser = chromium_launch::start(&profile, 1280, 800, Duration::from_secs(120));
    let tab = browser.new_tab().unwrap();
    for p in PICTURES {
        let page = work.join(p.run).join("view.html");
        if !page.is_file() {
            continue;
        }
        tab.navigate_to("about:blank").unwrap();
        tab.wait_until_navigated().unwrap();
        let url = format!(
            "file://{}{}",
            page.canonicalize().unwrap().display(),
            p.hash
        );
        tab.navigate_to(&url).unwrap();
        let t0 = Instant::now();
        loop {
            let ready = tab
                .evaluate("!!(window.applesimView && applesimView.ready)", false)
                .ok()
                .and_then(|r| r.value)
                .and_then(|v| v.as_bool())
                .unwrap_or(false);
            if ready {
                break;
            }
            assert!(
                t0.elapsed() < Duration::from_secs(60),
                "{} did not start",
                p.file
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        // Two frames drawn after the link's view was applied.
        tab.evaluate(
            "new Promise(r => requestAnimationFrame(() => requestAnimationFrame(() => setTimeout(() => r(1), 200))))",
            true,
        )
        .unwrap();
        let png = tab
            .capture_screenshot(CaptureScreenshotFormatOption::Png, None, None, true)
            .unwrap();
        std::fs::write(out.join(p.file), png).unwrap();
        println!("{}: {} ({}{})", p.file, p.what, p.run, p.hash);
    }
    drop(tab);
    drop(browser);
    let _ = std::fs::remove_dir_all(&work);
}
