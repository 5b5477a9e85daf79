//! Headless Chromium as the viewer's browser test (tests/view_browser.rs) and its timing
//! example (examples/view_timing.rs) start it: one binary lookup and one set of flags, so that
//! the figures of docs/viewer.md are taken in the browser the tests check.

use headless_chrome::{Browser, LaunchOptions};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The Chromium binary (`APPLESIM_CHROMIUM`, else Debian's and the usual places), or a failure
/// that says how to get it.
pub fn chromium() -> PathBuf {
    if let Some(p) = std::env::var_os("APPLESIM_CHROMIUM") {
        return PathBuf::from(p);
    }
    for p in [
        "/usr/bin/chromium",
        "/usr/bin/chromium-browser",
        "/usr/bin/google-chrome",
    ] {
        if Path::new(p).is_file() {
            return PathBuf::from(p);
        }
    }
    panic!(
        "Chromium is needed for the viewer's browser test and was not found (/usr/bin/chromium). \
         Install it with `apt-get update && apt-get install -y chromium` (as root; tools/test does \
         this), or set APPLESIM_CHROMIUM to a Chromium or Chrome binary."
    );
}

/// Starts headless Chromium with the user profile folder `profile`, a `width` x `height`
/// window, closing itself after `idle` without a command. The flags are those that work on
/// these machines (no GPU, no sandbox as root, nothing from the network); WebGL runs on
/// SwiftShader, the CPU renderer Chromium ships.
pub fn start(profile: &Path, width: u32, height: u32, idle: Duration) -> Browser {
    let path = chromium();
    let args: Vec<&OsStr> = [
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--hide-scrollbars",
    ]
    .iter()
    .map(OsStr::new)
    .collect();
    let opts = LaunchOptions::default_builder()
        .path(Some(path.clone()))
        .headless(true)
        .sandbox(false)
        .window_size(Some((width, height)))
        .user_data_dir(Some(profile.to_path_buf()))
        .args(args)
        .idle_browser_timeout(idle)
        .build()
        .unwrap();
    Browser::new(opts)
        .unwrap_or_else(|e| panic!("could not start {} headless: {e}", path.display()))
}
