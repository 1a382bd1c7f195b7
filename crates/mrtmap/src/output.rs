//! What the commands share for output: JSON text, progress bars, and the printed forms of maps
//! and stages.

use mrtmap_pipeline::StageOutcome;
use mrtmap_pipeline::maps::Summary;

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

impl mrtmap_pipeline::Progress for Bar {
    fn begin(&self, what: &str) {
        self.0.set_message(what.to_string());
    }

    fn advance(&self, done: u64, total: u64) {
        self.0.set_length(total);
        self.0.set_position(done);
    }
}

/// Prints a map's extremes and marks.
pub fn print_map(s: &Summary) {
    match &s.map.field {
        Some(f) => {
            println!(
                "MRT at {:.2} m over {} nodes: min {:.2} °C at ({:.2}, {:.2}), max {:.2} °C at ({:.2}, {:.2}), mean {:.2} °C; largest standard error {:.3} K",
                s.map.height_m,
                f.nodes,
                f.min.mrt_c,
                f.min.uv[0],
                f.min.uv[1],
                f.max.mrt_c,
                f.max.uv[0],
                f.max.uv[1],
                f.mean_c,
                f.max_std_error_k
            );
            if f.skipped > 0 {
                println!(
                    "{} nodes skipped (inside occluders or failed): see the note column of mrt_grid.csv",
                    f.skipped
                );
            }
        }
        None => println!("no grid node could be computed"),
    }
    for m in &s.marks {
        println!(
            "  {}: MRT {:.2} °C ± {:.2} K at ({:.2}, {:.2}, {:.2})",
            m.name.as_deref().unwrap_or("?"),
            m.mrt_c,
            m.std_error_k,
            m.xyz[0],
            m.xyz[1],
            m.xyz[2]
        );
    }
}

/// Prints one line per stage: its time, and whether it was reused.
pub fn print_stages(stages: &[StageOutcome]) {
    for st in stages {
        println!(
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
    print_stages(&o.stages);
    for m in &o.maps {
        print_map(&m.summary);
    }
    for w in &o.warnings {
        println!("warning: {w}");
    }
    println!(
        "done in {secs:.1} s; report: {}",
        out.join("report.html").display()
    );
}

/// Prints what a conversion wrote.
pub fn print_conversion(c: &mrtmap_pipeline::source::Conversion) {
    let from = |s: &Option<String>| s.as_ref().map(|s| format!(" ({s})")).unwrap_or_default();
    println!(
        "wrote {}: {} depth, {} thermal{}, {} colour frames, {} poses{}{}",
        c.out.display(),
        c.depth,
        c.thermal,
        from(&c.thermal_from),
        c.rgb,
        c.poses,
        from(&c.poses_from),
        if c.skipped > 0 {
            format!("; skipped {} {}", c.skipped, c.skipped_unit)
        } else {
            String::new()
        }
    );
    for r in &c.skipped_reasons {
        println!("  skipped: {r}");
    }
    for n in &c.notes {
        println!("  note: {n}");
    }
}

/// Prints the streams a bag's scan would use, and what it lacks.
pub fn print_plan(p: &mrtmap_sources::ros::Plan) {
    use mrtmap_sources::ros::PoseSource;
    let show = |o: &Option<String>| o.clone().unwrap_or_else(|| "—".into());
    println!("for a scan:");
    println!("  depth    {}", show(&p.depth));
    println!("  thermal  {}", show(&p.thermal));
    println!("  colour   {}", show(&p.rgb));
    println!(
        "  poses    {}",
        match &p.poses {
            Some(PoseSource::Topic(t)) => t.clone(),
            Some(PoseSource::Tf(a, b)) => format!("/tf {a} → {b}"),
            None => "—".into(),
        }
    );
    for n in &p.notes {
        println!("  note: {n}");
    }
    print_missing(&p.missing);
}

/// Prints whether a source is ready for a scan, or what it lacks.
pub fn print_missing(missing: &[String]) {
    if missing.is_empty() {
        println!("ready: mrtmap convert / fuse / run can use it");
    } else {
        println!("missing for a scan:");
        for m in missing {
            println!("  - {m}");
        }
    }
}
