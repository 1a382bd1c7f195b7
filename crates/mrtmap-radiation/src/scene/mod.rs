//! The radiant scene file (`scene.json`, format `mrtmap-scene/1`) and its validated model.
//!
//! [`SceneFile`] is the file as data (serde, every key of the spec plus the optional ones;
//! [`file`](mod@file)); [`RadiantScene`] is a scene that passed every rule of the scene format
//! (docs/scene-format.md), with each surface's plane frame computed once ([`model`]). Conversion
//! goes through [`RadiantScene::new`] ([`validate`], against the [`limits`]), whose errors
//! ([`error`]) name the surface, feature or occluder id and the rule broken; [`read`] parses JSON
//! text or a file into it. A surface's temperature raster is checked and radiates in [`raster`].

mod error;
mod file;
mod limits;
mod model;
mod raster;
mod read;
mod validate;

pub use error::{SceneError, SceneLoadError, SceneLoadErrorKind};
pub use file::{
    BoxFile, FeatureFile, FramePose, OccluderFile, RasterFile, SCENE_FORMAT, SceneFile,
    SurfaceFile, TemperatureKind, UnseenPatch, slug,
};
pub use limits::{
    FEATURE_PLANE_TOLERANCE_M, MAX_COORDINATE_M, PLANARITY_TOLERANCE_M, TEMPERATURE_RANGE_C,
};
pub use model::{Feature, Occluder, OccluderShape, RadiantScene, Surface, SurfaceKind};
pub use raster::{MAX_TEXELS, Raster, Texel, UnseenShare};
