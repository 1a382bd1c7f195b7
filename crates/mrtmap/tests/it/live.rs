//! `mrtmap live` following a scan replayed at its own pace (`mrtmap replay`), as a person on
//! site would: the state answers every second and keeps up, the page loads in a browser, a bad
//! frame is named and the view goes on, and the final run is `mrtmap run`'s.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::ok;
use crate::pipeline::recording;

/// GET `path` from the live server (HTTP/1.0: the server closes the connection after answering).
fn get(addr: &str, path: &str) -> Option<(String, String)> {
    let mut s = TcpStream::connect(addr).ok()?;
    s.set_read_timeout(Some(Duration::from_secs(5))).ok()?;
    s.write_all(format!("GET {path} HTTP/1.0\r\nHost: {addr}\r\n\r\n").as_bytes())
        .ok()?;
    let mut text = String::new();
    s.read_to_string(&mut text).ok()?;
    let (head, body) = text.split_once("\r\n\r\n")?;
    Some((head.to_string(), body.to_string()))
}

/// What the test saw of the state while following.
struct Watched {
    states: usize,
    last_fused: u64,
    worst_behind: f64,
    last: Value,
}

/// Asks for the state every second until `live` exits: each answer within a second, frames_fused
/// never going back; a wrong-size frame injected once 60 frames are fused; the event stream read
/// once; the page shown in a browser once the room model has been refreshed.
fn watch(live: &mut std::process::Child, addr: &str, rec: &Path, dir: &Path) -> Watched {
    let (mut states, mut last_fused, mut worst_behind, mut injected, mut shot) =
        (0, 0, 0.0f64, false, None);
    let mut last: Value = Value::Null;
    while live.try_wait().unwrap().is_none() {
        let asked = Instant::now();
        let Some((_, body)) = get(addr, "/state.json") else {
            // The server goes when the final run is done.
            std::thread::sleep(Duration::from_millis(200));
            continue;
        };
        assert!(
            asked.elapsed() < Duration::from_secs(1),
            "/state.json took {:?}",
            asked.elapsed()
        );
        let s: Value = serde_json::from_str(&body).unwrap();
        if s["phase"] == "following" {
            states += 1;
            let fused = s["frames_fused"].as_u64().unwrap();
            assert!(
                fused >= last_fused,
                "frames_fused went back: {fused} < {last_fused}"
            );
            last_fused = fused;
            worst_behind = worst_behind.max(s["behind_s"].as_f64().unwrap());
            if !injected && fused > 60 {
                inject_wrong_size_frame(rec);
                injected = true;
            }
            if states == 3 {
                // Pushed: two states a second apart, without asking again.
                let e = events(addr, 2);
                assert_eq!(e.len(), 2);
                assert!(e[1]["elapsed_s"].as_f64() > e[0]["elapsed_s"].as_f64());
            }
            if shot.is_none() && s["refreshes"].as_u64().unwrap() >= 1 {
                // In a thread of its own: the state is still asked for every second meanwhile.
                let (addr, dir) = (addr.to_string(), dir.to_path_buf());
                shot = Some(std::thread::spawn(move || {
                    screenshot_live_page(&addr, &dir);
                }));
            }
            last = s;
        }
        std::thread::sleep(Duration::from_secs(1).saturating_sub(asked.elapsed()));
    }
    if let Some(t) = shot {
        t.join().unwrap();
    }
    Watched {
        states,
        last_fused,
        worst_behind,
        last,
    }
}

/// The first `n` events of the state's stream.
fn events(addr: &str, n: usize) -> Vec<Value> {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    s.write_all(format!("GET /events HTTP/1.1\r\nHost: {addr}\r\n\r\n").as_bytes())
        .unwrap();
    let mut lines = BufReader::new(s).lines().map_while(Result::ok);
    let head = lines.next().unwrap();
    assert!(head.starts_with("HTTP/1.1 200"), "{head}");
    let mut got = Vec::new();
    let mut event = String::new();
    for l in lines {
        if let Some(e) = l.strip_prefix("event: ") {
            event = e.to_string();
        } else if let Some(d) = l.strip_prefix("data: ") {
            assert_eq!(event, "state");
            got.push(serde_json::from_str(d).unwrap());
            if got.len() == n {
                break;
            }
        }
    }
    got
}

/// Appends a thermal line whose file is a frame of another size, just after the newest line. The
/// replay appends lines meanwhile: the line is written only while the list is as read (a replay
/// line landing between the read and the append put the injected one back in time, and the final
/// run refused the list).
fn inject_wrong_size_frame(rec: &Path) {
    image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_pixel(40, 30, image::Luma([29315]))
        .save(rec.join("thermal/wrong_size.png"))
        .unwrap();
    loop {
        let list = std::fs::read_to_string(rec.join("thermal.txt")).unwrap();
        let last: f64 = list
            .lines()
            .rev()
            .find(|l| !l.starts_with('#'))
            .and_then(|l| l.split_whitespace().next())
            .and_then(|t| t.parse().ok())
            .unwrap();
        let mut f = std::fs::OpenOptions::new()
            .append(true)
            .open(rec.join("thermal.txt"))
            .unwrap();
        if !list.ends_with('\n') || f.metadata().unwrap().len() != list.len() as u64 {
            continue; // the replay is writing: read again
        }
        f.write_all(format!("{:.6} thermal/wrong_size.png\n", last + 0.001).as_bytes())
            .unwrap();
        return;
    }
}

#[test]
fn live_follows_a_replayed_scan_and_ends_with_the_full_run() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("rec");
    let out = dir.path().join("out");
    let mut replay = Command::new(env!("CARGO_BIN_EXE_mrtmap"))
        .args([
            "replay",
            recording().to_str().unwrap(),
            "--into",
            rec.to_str().unwrap(),
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !rec.join("rig.toml").exists() && t0.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let mut live = Command::new(env!("CARGO_BIN_EXE_mrtmap"))
        .args(["live", rec.to_str().unwrap(), "--serve", "127.0.0.1:0"])
        .args(["--out", out.to_str().unwrap(), "--exit-when-idle", "3"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (tx, rx) = std::sync::mpsc::channel::<String>();
    let stderr = live.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut all = String::new();
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line.clone());
            all.push_str(&line);
            all.push('\n');
        }
        all
    });
    let first = rx.recv_timeout(Duration::from_secs(60)).unwrap();
    let addr = first
        .split("http://")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .unwrap_or_else(|| panic!("no address in {first}"))
        .to_string();
    let (head, page) = get(&addr, "/").unwrap();
    assert!(
        head.starts_with("HTTP/1.") && head.contains(" 200 OK"),
        "{head}"
    );
    assert!(
        page.contains("<title>mrtmap live</title>") && page.contains("EventSource(\"/events\")")
    );
    assert!(
        !page.contains("http://") && !page.contains("https://"),
        "the page loads nothing from outside"
    );
    let Watched {
        states,
        last_fused,
        worst_behind,
        last,
    } = watch(&mut live, &addr, &rec, dir.path());
    let status = live.wait().unwrap();
    let said = reader.join().unwrap();
    assert!(status.success(), "mrtmap live failed: {said}");
    assert!(replay.wait().unwrap().success());
    // 20 s of scan at its own pace, answered every second.
    assert!(states >= 15, "{states} states while following");
    assert!(
        worst_behind <= 3.0,
        "fusion fell {worst_behind} s of scan behind"
    );
    assert!(last["refreshes"].as_u64().unwrap() >= 3, "{last}");
    assert!(last["map_max_std_error_k"].as_f64().is_some(), "{last}");
    assert!(last["camera"]["position"].is_array(), "{last}");
    assert!(!last["surfaces"].as_array().unwrap().is_empty(), "{last}");
    assert!(last["latency_median_s"].as_f64().unwrap() < 1.0, "{last}");
    // The bad frame is named on the page's state and on the terminal, and fusion went on.
    let named = |w: &Value| w.as_str().is_some_and(|w| w.contains("wrong_size.png"));
    assert!(
        last["warnings"].as_array().unwrap().iter().any(named),
        "{last}"
    );
    assert!(
        said.contains("warning: fusion skipped a frame") && said.contains("wrong_size.png"),
        "{said}"
    );
    assert!(last["frames_fused"].as_u64().unwrap() > last_fused.min(150) - 10);
    // The final run is what `mrtmap run` makes of the finished recording.
    let reference = dir.path().join("reference");
    ok(&[
        "run",
        rec.to_str().unwrap(),
        "--out",
        reference.to_str().unwrap(),
    ]);
    let grid = |d: &Path| -> Vec<f64> {
        let text = std::fs::read_to_string(d.join("map-1.10m/mrt_grid.csv")).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let k = header.iter().position(|h| *h == "mrt_c").unwrap();
        lines
            .map(|l| {
                l.split(',')
                    .nth(k)
                    .unwrap()
                    .parse::<f64>()
                    .unwrap_or(f64::NAN)
            })
            .collect()
    };
    let (a, b) = (grid(&out), grid(&reference));
    assert_eq!(a.len(), b.len());
    assert!(a.len() >= 100);
    for (x, y) in a.iter().zip(&b) {
        assert!(
            x.is_nan() && y.is_nan() || (x - y).abs() <= 0.05,
            "{x} vs {y}"
        );
    }
    assert!(out.join("report.html").is_file());
}

/// The page in a real browser while the scan is replayed: the verdict, the advice and the scan's
/// figures are filled in from the pushed state, and the 3D view is drawn.
fn screenshot_live_page(addr: &str, dir: &Path) {
    let Some(chrome) = crate::pipeline::Chrome::find(dir) else {
        return;
    };
    let url = format!("http://{addr}/#once");
    let budget = ["--window-size=1400,900", "--virtual-time-budget=4000"];
    let dom = chrome.run(&[&budget[..], &["--dump-dom", &url]].concat());
    let dom = String::from_utf8_lossy(&dom.stdout);
    let fused = dom
        .split("<td id=\"fused\">")
        .nth(1)
        .and_then(|r| r.split('<').next())
        .and_then(|n| n.parse::<u64>().ok());
    assert!(
        fused.is_some_and(|n| n > 0),
        "the page shows no frames fused: {}",
        &dom[..dom.len().min(2000)]
    );
    assert!(dom.contains("id=\"verdict\""));
    let shot = dir.join("live.png");
    let s = chrome.run(
        &[
            &budget[..],
            &[&format!("--screenshot={}", shot.display()), &url],
        ]
        .concat(),
    );
    assert!(s.status.success());
    assert!(
        std::fs::metadata(&shot).unwrap().len() > 20_000,
        "a blank screenshot"
    );
    // The 3D view the page frames, alone.
    let shot3d = dir.join("live-view3d.png");
    let s = chrome.run(&[
        "--window-size=1000,800",
        "--virtual-time-budget=5000",
        &format!("--screenshot={}", shot3d.display()),
        &format!("http://{addr}/view.html"),
    ]);
    assert!(s.status.success());
    crate::pipeline::assert_view3d_drawn(&shot3d);
    if let Some(keep) = std::env::var_os("MRTMAP_KEEP_SCREENSHOTS") {
        let _ = std::fs::copy(&shot, Path::new(&keep).join("live.png"));
        let _ = std::fs::copy(&shot3d, Path::new(&keep).join("live-view3d.png"));
    }
}

/// Ctrl-C once stops following and makes the full run (exit 0); twice stops at once (exit 130).
#[test]
fn ctrl_c_once_makes_the_full_run_and_twice_stops_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let start = |out: &Path| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_mrtmap"))
            .args([
                "live",
                recording().to_str().unwrap(),
                "--serve",
                "127.0.0.1:0",
            ])
            .args(["--out", out.to_str().unwrap()])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
        let first = lines.next().unwrap().unwrap();
        let addr = first
            .split("http://")
            .nth(1)
            .unwrap()
            .split_whitespace()
            .next()
            .unwrap()
            .to_string();
        // Following: every frame of the finished recording is fused.
        let t0 = Instant::now();
        loop {
            let s: Value = serde_json::from_str(&get(&addr, "/state.json").unwrap().1).unwrap();
            if s["frames_fused"].as_u64().unwrap_or(0) > 100 {
                break;
            }
            assert!(t0.elapsed() < Duration::from_secs(60), "{s}");
            std::thread::sleep(Duration::from_millis(300));
        }
        let rest =
            std::thread::spawn(move || lines.map_while(Result::ok).collect::<Vec<_>>().join("\n"));
        (child, rest)
    };
    let interrupt = |pid: u32| {
        assert!(
            Command::new("kill")
                .args(["-INT", &pid.to_string()])
                .status()
                .unwrap()
                .success()
        );
    };
    let once = dir.path().join("once");
    let (mut child, rest) = start(&once);
    interrupt(child.id());
    let status = child.wait().unwrap();
    let said = rest.join().unwrap();
    assert!(status.success(), "{said}");
    assert!(
        said.contains("stopping: following ends and the full run is made"),
        "{said}"
    );
    assert!(once.join("report.html").is_file());
    let twice = dir.path().join("twice");
    let (mut child, rest) = start(&twice);
    interrupt(child.id());
    std::thread::sleep(Duration::from_millis(300));
    interrupt(child.id());
    let status = child.wait().unwrap();
    let said = rest.join().unwrap();
    assert_eq!(status.code(), Some(130), "{said}");
    assert!(
        said.contains("interrupted: every file already written is complete"),
        "{said}"
    );
    assert!(
        !twice.join("report.html").exists(),
        "the full run was not stopped"
    );
}

/// A folder that does not exist and a bad setting are refused before the page opens (the page's
/// address and a promise of a full run were printed first).
#[test]
fn a_bad_live_request_is_refused_before_the_page_opens() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    // Issue 63: a folder of the user's (their own report.html in it) and the recording itself
    // are refused before following, not after the whole scan.
    let users = dir.path().join("mine");
    std::fs::create_dir_all(&users).unwrap();
    std::fs::write(users.join("report.html"), "my notes").unwrap();
    for (rec, extra, says, out) in [
        (
            dir.path().join("nope"),
            None,
            "start the recorder first",
            &out,
        ),
        (
            recording().to_path_buf(),
            Some("0"),
            "--exit-when-idle 0",
            &out,
        ),
        (
            recording().to_path_buf(),
            None,
            "mrtmap did not write there",
            &users,
        ),
        (
            recording().to_path_buf(),
            None,
            "is the recording folder itself",
            &recording().to_path_buf(),
        ),
    ] {
        let mut args = vec![
            "live".to_string(),
            rec.display().to_string(),
            "--serve".into(),
            "127.0.0.1:0".into(),
            "--out".into(),
            out.display().to_string(),
        ];
        if let Some(s) = extra {
            args.extend(["--exit-when-idle".into(), s.into()]);
        }
        let o = Command::new(env!("CARGO_BIN_EXE_mrtmap"))
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(says), "{err}");
        assert!(!err.contains("live page:"), "{err}");
    }
    assert_eq!(
        std::fs::read_to_string(users.join("report.html")).unwrap(),
        "my notes"
    );
}

/// Served beyond this machine (0.0.0.0), `live` says so on one line before the page's address;
/// on 127.0.0.1 it does not. Either way the page answers, and refuses to be changed.
#[test]
fn serving_to_the_network_is_announced() {
    for (serve, announced) in [("0.0.0.0:0", true), ("127.0.0.1:0", false)] {
        let dir = tempfile::tempdir().unwrap();
        let mut live = Command::new(env!("CARGO_BIN_EXE_mrtmap"))
            .args(["live", recording().to_str().unwrap(), "--serve", serve])
            .args(["--out", dir.path().join("out").to_str().unwrap()])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let stderr = live.stderr.take().unwrap();
        let mut before = Vec::new();
        let mut page = None;
        for line in BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
            .take(20)
        {
            if line.starts_with("live page: http://") {
                page = Some(line);
                break;
            }
            before.push(line);
        }
        let page = page.unwrap_or_else(|| panic!("no page's address after {before:?}"));
        let port = page
            .split("http://")
            .nth(1)
            .and_then(|r| r.split_whitespace().next())
            .and_then(|a| a.rsplit_once(':'))
            .map(|(_, p)| p.to_string())
            .unwrap();
        let addr = format!("127.0.0.1:{port}");
        let (head, _) = get(&addr, "/state.json").unwrap();
        assert!(head.starts_with("HTTP/1.1 200"), "{head}");
        let mut s = TcpStream::connect(&addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        s.write_all(b"POST /state.json HTTP/1.0\r\nContent-Length: 2\r\n\r\n{}")
            .unwrap();
        let mut answer = String::new();
        let _ = s.read_to_string(&mut answer);
        live.kill().unwrap();
        live.wait().unwrap();
        assert!(answer.starts_with("HTTP/1.1 405"), "{answer}");
        assert!(answer.contains("Allow: GET, HEAD"), "{answer}");
        let notices: Vec<_> = before.iter().filter(|l| l.starts_with("notice:")).collect();
        if announced {
            assert_eq!(notices.len(), 1, "{before:?}");
            assert!(
                notices[0].contains("anyone on the network can read the live page"),
                "{before:?}"
            );
        } else {
            assert!(notices.is_empty(), "{before:?}");
        }
    }
}
