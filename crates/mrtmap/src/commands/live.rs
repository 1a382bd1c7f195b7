//! `mrtmap live` and `mrtmap replay`: following a scan as it is recorded, and recording one again
//! at its own pace.

use std::sync::Mutex;
use std::sync::atomic::Ordering;

use mrtmap_pipeline::live::{
    LiveOptions, LiveSink, LiveState, check_live_out, live, replay::replay as replay_into,
};
use mrtmap_pipeline::{Overrides, Pipeline, Project};

use crate::cli::{LiveArgs, ReplayArgs};
use crate::output::print_lines;
use crate::{STOP, STOP_GRACEFULLY};

pub fn run(a: &LiveArgs) -> anyhow::Result<()> {
    let project = Project::resolve(a.config.as_deref(), &Overrides::new())?;
    project.check_heights_above_floor()?;
    if !(a.target_k.is_finite() && a.target_k > 0.0 && a.target_k <= 10.0) {
        anyhow::bail!(
            "--target-k {}: give the map's target as a positive number of kelvin (2σ), at most 10",
            a.target_k
        );
    }
    if let Some(s) = a.exit_when_idle.filter(|s| !(s.is_finite() && *s > 0.0)) {
        anyhow::bail!("--exit-when-idle {s}: give a positive number of seconds");
    }
    check_live_out(&a.recording, &a.out)?;
    let server = mrtmap_live::Server::start(&a.serve)?;
    eprintln!(
        "live page: http://{} (state: /state.json); following {}; Ctrl-C stops following and makes the full run into {}",
        server.addr(),
        a.recording.display(),
        a.out.display()
    );
    STOP_GRACEFULLY.store(true, Ordering::SeqCst);
    let opts = LiveOptions {
        target_k: a.target_k,
        exit_when_idle_s: a.exit_when_idle,
        ..LiveOptions::default()
    };
    let pipeline = Pipeline::new(project);
    let sink = Terminal {
        server: &server,
        said: Mutex::new((0, String::new())),
    };
    let done = live(&pipeline, &a.recording, &a.out, &opts, &STOP, &sink)?;
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
        if s.verdict != said.1 || s.phase != "following" {
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
    let done = replay_into(&a.recording, &a.into, a.speed, &STOP, &|t, total| {
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
