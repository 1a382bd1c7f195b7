//! Progress reporting: the pipeline says what it is doing and how far it is; the CLI draws bars.

/// Receives progress from long steps. Implementations must be cheap: `advance` is called once per
/// frame from worker threads.
pub trait Progress: Sync {
    /// A new step begins, described for people ("fusing thermal frames").
    fn begin(&self, what: &str);
    /// `done` of `total` units of the current step.
    fn advance(&self, done: u64, total: u64);
    /// Whether the run should stop (a person pressed Ctrl-C); the pipeline asks between stages
    /// and answers [`Error::Stopped`](crate::Error::Stopped). Never, by default.
    fn stopped(&self) -> bool {
        false
    }
}

/// Progress that goes nowhere.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Progress for Silent {
    fn begin(&self, _what: &str) {}
    fn advance(&self, _done: u64, _total: u64) {}
}
