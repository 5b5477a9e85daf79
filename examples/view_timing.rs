//! Load time and playback rate of viewer pages in headless Chromium (docs/viewer.md).
//!
//! ```sh
//! cargo run --release --example view_timing -- out/view_pile/view.html out/view_line/view.html
//! ```
//!
//! For each page: its size, the time from the start of navigation to the first frame drawn
//! (`performance.now()` when the page is ready, measured by the browser itself; median of three
//! fresh loads), the cost of moving and colouring the apples for one frame (update) and of drawing
//! it (draw: `renderer.render` and a read of one pixel, which waits until the frame is drawn;
//! `gl.finish()` does not wait in Chromium), the draw calls and triangles of that frame, then the frames drawn per second over 5 s of playback at 1x after a click on Play. Chromium renders WebGL on the CPU here
//! (SwiftShader, no GPU): a desktop browser with a GPU draws at least as fast.

#[path = "../tests/chromium_launch/mod.rs"]
mod chromium_launch;

use headless_chrome::browser::tab::point::Point;
use std::path::PathBuf;
use std::time::{Duration, Instant};

fn main() {
    let pages: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if pages.is_empty() {
        eprintln!("usage: view_timing PAGE.html ...");
        std::process::exit(2);
    }
    let profile = std::env::temp_dir().join(format!("applesim-view-timing-{}", std::process::id()));
    let browser = chromium_launch::start(&profile, 1280, 800, Duration::from_secs(300));
    println!("| page | size (MB) | apples | frames | load to first frame (ms, median of 3) | playback (frames/s) | update (ms) | draw (ms) | draw calls | triangles | load average |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for page in &pages {
        let url = format!("file://{}", page.canonicalize().unwrap().display());
        let size = std::fs::metadata(page).unwrap().len() as f64 / 1e6;
        let mut loads = Vec::new();
        let tab = browser.new_tab().unwrap();
        for _ in 0..3 {
            tab.navigate_to("about:blank").unwrap();
            std::thread::sleep(Duration::from_millis(300));
            tab.navigate_to(&url).unwrap();
            let t0 = Instant::now();
            let ms = loop {
                let v = tab
                    .evaluate(
                        "window.applesimView && window.applesimView.ready ? applesimView.readyAtMs : -1",
                        false,
                    )
                    .ok()
                    .and_then(|r| r.value)
                    .and_then(|v| v.as_f64())
                    .unwrap_or(-1.0);
                if v >= 0.0 {
                    break v;
                }
                assert!(
                    t0.elapsed() < Duration::from_secs(120),
                    "{} did not start",
                    page.display()
                );
                std::thread::sleep(Duration::from_millis(20));
            };
            loads.push(ms);
        }
        loads.sort_by(f64::total_cmp);
        let info = tab
            .evaluate(
                "JSON.stringify([applesimView.apples.userData.count, applesimView.frameTimes.length, \
                 (r => [r.left + r.width / 2, r.top + r.height / 2])(document.getElementById('play').getBoundingClientRect())])",
                false,
            )
            .unwrap()
            .value
            .unwrap();
        let info: serde_json::Value = serde_json::from_str(info.as_str().unwrap()).unwrap();
        // The cost of one frame's two parts: moving and colouring the apples (the slider's input
        // handler: update()) and drawing (renderer.render, then gl.readPixels of one pixel: the
        // browser must finish drawing the frame to answer; median of 7).
        let prof = tab
            .evaluate(
                "(() => { const V = applesimView, s = document.getElementById('slider'); \
                 const n = V.frameTimes.length; let t0 = performance.now(); \
                 for (let i = 0; i < 10; i++) { s.value = String(Math.floor(n * (i + 1) / 12)); s.dispatchEvent(new Event('input')); } \
                 const u = (performance.now() - t0) / 10; const gl = V.renderer.getContext(); \
                 const px = new Uint8Array(4), ds = []; \
                 for (let i = 0; i < 8; i++) { t0 = performance.now(); V.renderer.render(V.scene, V.camera); \
                 gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px); ds.push(performance.now() - t0); } \
                 const r = ds.slice(1).sort((a, b) => a - b)[3], info = V.renderer.info.render; \
                 s.value = '0'; s.dispatchEvent(new Event('input')); \
                 return JSON.stringify([u, r, info.calls, info.triangles]); })()",
                false,
            )
            .unwrap()
            .value
            .unwrap();
        let prof: serde_json::Value = serde_json::from_str(prof.as_str().unwrap()).unwrap();
        // Count the frames the page draws while it plays (a counter beside the page's own
        // requestAnimationFrame loop).
        tab.evaluate(
            "window.__frames = 0; (function tick() { window.__frames++; requestAnimationFrame(tick); })(); 'ok'",
            false,
        )
        .unwrap();
        let (x, y) = (info[2][0].as_f64().unwrap(), info[2][1].as_f64().unwrap());
        tab.click_point(Point { x, y }).unwrap();
        let t0 = Instant::now();
        let frames = || {
            tab.evaluate("window.__frames", false)
                .unwrap()
                .value
                .unwrap()
                .as_f64()
                .unwrap()
        };
        let f0 = frames();
        std::thread::sleep(Duration::from_secs(5));
        let f1 = frames();
        let fps = (f1 - f0) / t0.elapsed().as_secs_f64();
        println!(
            "| {} | {:.1} | {} | {} | {:.0} ({:.0}-{:.0}) | {:.1} | {:.1} | {:.1} | {} | {} | {} |",
            page.display(),
            size,
            info[0],
            info[1],
            loads[1],
            loads[0],
            loads[2],
            fps,
            prof[0].as_f64().unwrap(),
            prof[1].as_f64().unwrap(),
            prof[2],
            prof[3],
            // The machine's 1-minute load average after playback (other work shares its cores).
            std::fs::read_to_string("/proc/loadavg")
                .ok()
                .and_then(|l| l.split(' ').next().map(String::from))
                .unwrap_or_default()
        );
        tab.close(false).ok();
    }
    let _ = std::fs::remove_dir_all(profile);
}
