//! What the commands share for output: JSON text, progress bars, and the printed forms of maps
//! and stages.

use std::io::Write;

use mrtmap_pipeline::StageOutcome;
use mrtmap_pipeline::maps::Summary;
use mrtmap_pipeline::report::numbers::{fixed, uncertainty, xyz};

/// Like `println!`, but a closed pipe (`mrtmap rooms | head -1`) ends the program quietly.
macro_rules! outln {
    () => {
        $crate::output::write_stdout(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::output::write_stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// Like `print!`, but a closed pipe ends the program quietly.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::output::write_stdout(format_args!($($arg)*))
    };
}

/// Writes to standard output. When the reader has gone (a closed pipe) the program ends quietly
/// with success, as Unix tools do; any other failure to write ends it with a message.
pub fn write_stdout(args: std::fmt::Arguments<'_>) {
    let mut stdout = std::io::stdout().lock();
    if let Err(e) = stdout.write_fmt(args).and_then(|()| stdout.flush()) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!(
            "error: cannot write to standard output: {}",
            mrtmap_pipeline::files::io_words(&e)
        );
        std::process::exit(1);
    }
}

/// JSON text with a trailing newline.
pub fn json<T: serde::Serialize>(value: &T) -> anyhow::Result<String> {
    Ok(serde_json::to_string_pretty(value)? + "\n")
}

/// A progress bar on stderr.
pub struct Bar(indicatif::ProgressBar);

impl Bar {
    /// A bar with `unit` after the counts ("frames"), empty until the first step.
    pub fn new(unit: &str) -> Self {
        let bar = indicatif::ProgressBar::new(0);
        let template = format!("{{msg}} [{{bar:40}}] {{pos}}/{{len}}{unit} ({{eta}})");
        bar.set_style(
            indicatif::ProgressStyle::with_template(&template)
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        Self(bar)
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl Bar {
    /// The counts shown now (done, of).
    #[cfg(test)]
    fn counts(&self) -> (u64, u64) {
        (self.0.position(), self.0.length().unwrap_or(0))
    }
}

impl mrtmap_pipeline::Progress for Bar {
    fn begin(&self, what: &str) {
        // A new stage starts empty: the last stage's count under a new length read "522/1".
        self.0.set_position(0);
        self.0.set_length(0);
        self.0.set_message(what.to_string());
    }

    fn advance(&self, done: u64, total: u64) {
        // Position first when it falls, length first when it grows: never more done than in all.
        let done = done.min(total);
        if done < self.0.position() {
            self.0.set_position(done);
            self.0.set_length(total);
        } else {
            self.0.set_length(total);
            self.0.set_position(done);
        }
    }
}

/// Prints a map's extremes and marks.
pub fn print_map(s: &Summary) {
    match &s.map.field {
        Some(f) => {
            outln!(
                "MRT at {:.2} m over {} nodes: min {:.2} °C at ({}, {}), max {:.2} °C at ({}, {}), mean {:.2} °C; largest standard error {} K",
                s.map.height_m,
                f.nodes,
                f.min.mrt_c,
                fixed(f.min.uv[0], 2),
                fixed(f.min.uv[1], 2),
                f.max.mrt_c,
                fixed(f.max.uv[0], 2),
                fixed(f.max.uv[1], 2),
                f.mean_c,
                uncertainty(f.max_std_error_k, 3)
            );
            if f.skipped > 0 {
                outln!(
                    "{} nodes skipped (inside furniture, or refused): see the note column of mrt_grid.csv",
                    f.skipped
                );
            }
            outln!(
                "  its parts, the largest of each: {}",
                mrtmap_pipeline::report::parts_line(&f.max_std_error_parts, 3)
            );
            for u in f.unseen_patches.iter().take(3) {
                outln!("  not seen: {}", mrtmap_pipeline::report::unseen_line(u));
            }
        }
        None => outln!("no grid node could be computed"),
    }
    for m in &s.marks {
        outln!(
            "  {}: MRT {:.2} °C ± {} K at {}",
            m.name.as_deref().unwrap_or("?"),
            m.mrt_c,
            uncertainty(m.std_error_k, 2),
            xyz(&m.xyz)
        );
    }
}

/// Prints one line per stage: its time, and whether it was reused.
pub fn print_stages(stages: &[StageOutcome]) {
    for st in stages {
        outln!(
            "  {:<14} {:>7.1} s{}",
            st.stage,
            st.secs,
            if st.skipped {
                "  (inputs unchanged: reused)"
            } else {
                ""
            }
        );
    }
}

/// Prints a run's stages, maps and warnings, and where the report is.
pub fn print_run(o: &mrtmap_pipeline::run::RunOutcome, out: &std::path::Path, secs: f64) {
    if let Some(t) = &o.track {
        outln!(
            "poses from the built-in tracker (track/trajectory.txt): {} of {} colour frames, {} keyframes, {} loop closures{}",
            t.tracked,
            t.frames,
            t.keyframes,
            t.loops_accepted,
            t.accuracy
                .map(|e| format!(
                    "; against groundtruth.txt ATE {:.1} mm, drift over {:.1} s {:.1} mm, {:.2}°",
                    e.ate_rmse_m * 1000.0,
                    e.drift_span_s,
                    e.drift_translation_rmse_m * 1000.0,
                    e.drift_rotation_rmse_deg
                ))
                .unwrap_or_default()
        );
    }
    print_stages(&o.stages);
    outln!(
        "{} of {} thermal frames fused; {}",
        o.fusion.used_frames,
        o.fusion.thermal_frames,
        o.fusion.clock.describe()
    );
    for m in &o.maps {
        print_map(&m.summary);
    }
    for w in &o.warnings {
        outln!("warning: {w}");
    }
    outln!(
        "done in {secs:.1} s; report: {}",
        out.join("report.html").display()
    );
}

/// Prints what a conversion wrote.
pub fn print_conversion(c: &mrtmap_pipeline::source::Conversion) {
    let from = |s: &Option<String>| s.as_ref().map(|s| format!(" ({s})")).unwrap_or_default();
    outln!(
        "wrote {}: {} depth, {} thermal{}, {} colour frames, {} poses{}{}{}",
        c.out.display(),
        c.depth,
        c.thermal,
        from(&c.thermal_from),
        c.rgb,
        c.poses,
        from(&c.poses_from),
        if c.imu > 0 {
            format!(", {} inertial samples", c.imu)
        } else {
            String::new()
        },
        if c.skipped > 0 {
            format!("; skipped {} {}", c.skipped, c.skipped_unit)
        } else {
            String::new()
        }
    );
    for r in &c.skipped_reasons {
        outln!("  skipped: {r}");
    }
    for n in &c.notes {
        outln!("  note: {n}");
    }
}

/// Prints the streams a bag's scan would use, and what it lacks.
#[cfg(test)]
mod tests {
    use super::*;
    use mrtmap_pipeline::Progress;

    /// Issue 41: after fusing 522 frames the next stage's bar read "522/1".
    #[test]
    fn a_new_stage_starts_its_bar_empty() {
        let bar = Bar::new(" frames");
        bar.begin("fusing");
        bar.advance(522, 522);
        assert_eq!(bar.counts(), (522, 522));
        bar.begin("segmenting");
        assert_eq!(bar.counts(), (0, 0));
        bar.advance(0, 1);
        assert_eq!(bar.counts(), (0, 1));
        bar.advance(5, 3);
        assert_eq!(bar.counts(), (3, 3));
    }
}
