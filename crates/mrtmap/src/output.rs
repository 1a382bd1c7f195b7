//! What the commands share for output: JSON text, progress bars, and the printed forms of maps
//! and stages.

use std::io::Write;

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
        eprintln!("error: cannot write to standard output: {e}");
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

/// Prints each line.
pub fn print_lines(lines: impl IntoIterator<Item = String>) {
    for line in lines {
        outln!("{line}");
    }
}

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
