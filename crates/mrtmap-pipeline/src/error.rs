//! The pipeline's errors: each names the file, setting or stage it comes from.

use std::path::PathBuf;

use mrtmap_io::FileError;

/// Why a pipeline step failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written (the error names it).
    #[error(transparent)]
    File(#[from] FileError),
    /// A scene file could not be loaded.
    #[error(transparent)]
    SceneLoad(#[from] mrtmap_radiation::SceneLoadError),
    /// A scene broke a rule.
    #[error(transparent)]
    Scene(#[from] mrtmap_radiation::SceneError),
    /// An MRT could not be computed.
    #[error(transparent)]
    Mrt(#[from] mrtmap_radiation::MrtError),
    /// A grid could not be laid out.
    #[error(transparent)]
    Field(#[from] mrtmap_radiation::FieldError),
    /// A map or report could not be drawn.
    #[error(transparent)]
    Report(#[from] mrtmap_report::ReportError),
    /// The simulator refused its settings or failed.
    #[error(transparent)]
    Sim(#[from] mrtmap_sim::SimError),
    /// A room description is invalid.
    #[error(transparent)]
    Room(#[from] mrtmap_sim::RoomError),
    /// A physics formula refused its inputs.
    #[error(transparent)]
    Physics(#[from] mrtmap_physics::PhysicsError),
    /// Calibration failed.
    #[error(transparent)]
    Calib(#[from] mrtmap_calib::CalibError),
    /// Segmentation gave up on a cloud.
    #[error("cannot segment {}", cloud.display())]
    Segment {
        /// The cloud.
        cloud: PathBuf,
        /// Why.
        #[source]
        source: mrtmap_scan::segment::SegmentError,
    },
    /// The MRT at a named point failed.
    #[error("cannot compute the MRT at {name}")]
    Point {
        /// The point's name.
        name: String,
        /// Why.
        #[source]
        source: mrtmap_radiation::MrtError,
    },
    /// The run was stopped on request ([`Progress::stopped`](crate::Progress::stopped)) before
    /// `stage`; the stages before it are complete and reused by the next run.
    #[error("stopped before {stage}, as asked")]
    Stopped {
        /// The stage that did not run.
        stage: &'static str,
    },
    /// A map could not be laid over a scene.
    #[error("cannot map {scene}")]
    Map {
        /// Where the scene came from.
        scene: String,
        /// Why.
        #[source]
        source: mrtmap_radiation::FieldError,
    },
    /// A setting (flag or project.toml key) is out of range or inconsistent.
    #[error("{setting} {problem}")]
    Setting {
        /// The flag or key, with its value.
        setting: String,
        /// What is wrong and what is allowed, as the rest of a sentence ("is outside 0…1 m").
        problem: String,
    },
    /// A project file does not parse.
    #[error("{}:{line}: {message}", path.display())]
    Config {
        /// The file.
        path: PathBuf,
        /// 1-based line (0 when unknown).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A source cannot be made into a scan, or cannot be read as one.
    #[error("{}: {problem}", path.display())]
    Source {
        /// The source.
        path: PathBuf,
        /// What is wrong or missing, and what to do.
        problem: String,
    },
    /// A bag, MCAP or ROS 2 source lacks what a scan needs; the plan says what was chosen.
    #[error("{}: cannot make a scan of it: {}", path.display(), missing.join("; "))]
    NotAScan {
        /// The source.
        path: PathBuf,
        /// What it lacks.
        missing: Vec<String>,
        /// The streams chosen so far (bags, MCAP and ROS 2 bags).
        plan: Option<Box<mrtmap_sources::ros::Plan>>,
    },
    /// A JSON file the pipeline wrote earlier no longer reads.
    #[error("{}: {source}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// Why.
        source: serde_json::Error,
    },
}

impl Error {
    /// A setting out of range.
    pub fn setting(setting: impl Into<String>, problem: impl Into<String>) -> Self {
        Self::Setting {
            setting: setting.into(),
            problem: problem.into(),
        }
    }

    /// A source problem.
    pub fn source(path: &std::path::Path, problem: impl Into<String>) -> Self {
        Self::Source {
            path: path.to_path_buf(),
            problem: problem.into(),
        }
    }
}

/// The pipeline's result.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl From<mrtmap_sources::convert::ConvertError> for Error {
    fn from(e: mrtmap_sources::convert::ConvertError) -> Self {
        use mrtmap_sources::convert::ConvertError as C;
        match e {
            C::File(f) => Self::File(f),
            C::Source { path, problem } => Self::Source { path, problem },
            C::NotAScan { path, missing } => Self::NotAScan {
                path,
                missing,
                plan: None,
            },
            C::Setting { setting, problem } => Self::Setting { setting, problem },
        }
    }
}
