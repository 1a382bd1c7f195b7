//! `mrtmap live` and `mrtmap replay`: following a scan as it is recorded, and recording one again
//! at its own pace.

use std::sync::Mutex;
use std::sync::atomic::Ordering;

use mrtmap_pipeline::{LivePhase, LiveSink, LiveState, Overrides, Pipeline, Project};

use crate::cli::{LiveArgs, ReplayArgs};
use crate::output::print_lines;
use crate::{STOP, STOP_GRACEFULLY};

/// glibc raises its mmap threshold each time a large block is freed, after which large blocks
/// (a depth image, a frame's points) come from the heap, where the small blocks a growing
/// recording adds for good (a path per frame) keep them from being given back: followed at its
/// own pace, the 343 s scan grew the process from 396 to 1,274 MB. A fixed threshold (glibc's
/// default, 128 KiB) keeps large blocks mapped and returned when freed: 46–79 MB over the first
/// 85 s of the same replay, against 396 MB at 86 s.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[allow(unsafe_code)]
fn fixed_mmap_threshold() {
    // SAFETY: mallopt takes the allocator's lock and only sets one of its parameters.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 * 1024);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn fixed_mmap_threshold() {}

pub fn run(a: &LiveArgs) -> anyhow::Result<()> {
    fixed_mmap_threshold();
    let pipeline = Pipeline::new(Project::resolve(a.config.as_deref(), &Overrides::new())?);
    pipeline.check_live(&a.recording, &a.out, a.target_k, a.exit_when_idle)?;
    let server = mrtmap_live::Server::start(&a.serve)?;
    if !mrtmap_live::is_loopback(server.addr()) {
        eprintln!(
            "notice: serving on {} beyond this machine: anyone on the network can read the live page (it changes nothing); --serve 127.0.0.1:PORT keeps it to this machine",
            server.addr()
        );
    }
    eprintln!(
        "live page: http://{} (state: /state.json); following {}; Ctrl-C stops following and makes the full run into {}",
        server.addr(),
        a.recording.display(),
        a.out.display()
    );
    STOP_GRACEFULLY.store(true, Ordering::SeqCst);
    let sink = Terminal {
        server: &server,
        said: Mutex::new((0, String::new())),
    };
    let done = pipeline.live(
        &a.recording,
        &a.out,
        a.target_k,
        a.exit_when_idle,
        &STOP,
        &sink,
    )?;
    print_lines(done.lines(&a.recording, &a.out));
    Ok(())
}

/// The page, and on the terminal each new warning and each change of verdict.
struct Terminal<'a> {
    server: &'a mrtmap_live::Server,
    /// Warnings printed, and the verdict last printed.
    said: Mutex<(usize, String)>,
}

impl LiveSink for Terminal<'_> {
    fn state(&self, s: &LiveState) {
        self.server.state(s);
        let mut said = self
            .said
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        for w in s.warnings.iter().skip(said.0) {
            eprintln!("warning: {w}");
        }
        said.0 = said.0.max(s.warnings.len());
        let verdict = format!(
            "{} ({} of {} thermal frames fused)",
            s.verdict, s.frames_fused, s.frames_received
        );
        if s.verdict != said.1 || s.phase != LivePhase::Following {
            eprintln!("{}: {verdict}", s.phase);
            said.1 = s.verdict.clone();
        }
    }

    fn view(&self, html: String) {
        self.server.view(html);
    }
}

pub fn replay(a: &ReplayArgs) -> anyhow::Result<()> {
    STOP_GRACEFULLY.store(true, Ordering::SeqCst);
    let done = Pipeline::replay(&a.recording, &a.into, a.speed, &STOP, &|t, total| {
        eprintln!("replayed {t:.0} of {total:.0} s");
    })?;
    outln!(
        "replayed {:.1} s of scan into {} in {:.1} s: {} lines, {} files{}",
        done.scan_s,
        a.into.display(),
        done.secs,
        done.lines,
        done.files,
        if done.stopped {
            " (stopped before the end)"
        } else {
            ""
        }
    );
    Ok(())
}
