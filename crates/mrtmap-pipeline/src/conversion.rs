//! What a source conversion is told and what it reports: mrtmap-sources' types.

pub use mrtmap_sources::convert::{Conversion, SourceOptions};
