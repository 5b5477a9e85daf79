//! README's test command, `tools/test` (issue 28, "A fresh machine"): it runs `cargo test
//! --release` when a Chromium is there, installs Debian's `chromium` first when it is missing and
//! the user is root, and otherwise stops before testing (exit 1) with the command to run. Checked
//! with stand-ins for `id`, `apt-get` and `cargo` first on the PATH (each records its arguments),
//! so nothing is installed and the suite does not run itself.

use crate::common;
use common::repo;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A folder of stand-in commands: `id -u` prints `uid`; `apt-get` and `cargo` append their
/// arguments to `calls.txt` in the folder and succeed.
fn stand_ins(name: &str, uid: u32) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "applesim-test-command-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let calls = dir.join("calls.txt");
    let script = |file: &str, body: String| {
        let p = dir.join(file);
        std::fs::write(&p, format!("#!/bin/sh\n{body}\n")).unwrap();
        Command::new("chmod").arg("+x").arg(&p).status().unwrap();
    };
    script("id", format!("echo {uid}"));
    for tool in ["apt-get", "cargo"] {
        script(tool, format!("echo \"{tool} $*\" >> '{}'", calls.display()));
    }
    dir
}

/// Runs tools/test with the stand-ins first on the PATH and APPLESIM_CHROMIUM set to `chromium`:
/// (exit code, stderr, the recorded calls).
fn tools_test(dir: &Path, chromium: &str) -> (i32, String, String) {
    let path = format!("{}:{}", dir.display(), std::env::var("PATH").unwrap());
    let o = Command::new("bash")
        .arg(repo("tools/test"))
        .env("PATH", path)
        .env("APPLESIM_CHROMIUM", chromium)
        .env_remove("DEBIAN_FRONTEND")
        .output()
        .unwrap();
    let calls = std::fs::read_to_string(dir.join("calls.txt")).unwrap_or_default();
    (
        o.status.code().unwrap(),
        String::from_utf8_lossy(&o.stderr).to_string(),
        calls,
    )
}

#[test]
fn without_chromium_and_not_root_it_stops_with_the_command_to_run() {
    let dir = stand_ins("user", 1000);
    let (code, err, calls) = tools_test(&dir, "/nonexistent/chromium");
    println!("{err}");
    assert_eq!(code, 1);
    assert!(
        err.contains("apt-get update && apt-get install -y chromium"),
        "{err}"
    );
    assert!(err.contains("not root"), "{err}");
    assert_eq!(calls, "", "nothing installed, no test run");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn without_chromium_as_root_it_installs_debians_chromium_first() {
    let dir = stand_ins("root", 0);
    // The stand-in apt-get installs nothing, so the script says so after trying.
    let (code, err, calls) = tools_test(&dir, "/nonexistent/chromium");
    assert_eq!(
        calls, "apt-get update\napt-get install -y chromium\n",
        "{err}"
    );
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("still missing"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn with_chromium_it_runs_cargo_test_release() {
    let dir = stand_ins("ready", 1000);
    // Any executable stands for the browser here: the script only looks for it.
    let (code, err, calls) = tools_test(&dir, "/bin/true");
    assert_eq!(code, 0, "{err}");
    assert_eq!(calls, "cargo test --release\n");
    // And .ci/run runs exactly tools/test.
    let ci = std::fs::read_to_string(repo(".ci/run")).unwrap();
    assert!(ci.lines().any(|l| l.trim() == "exec tools/test"), "{ci}");
    let _ = std::fs::remove_dir_all(&dir);
}
