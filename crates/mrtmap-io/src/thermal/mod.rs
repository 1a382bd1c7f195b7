//! Single thermal images in camera formats: FLIR R-JPEG and FFF ([`flir`], with the file's Planck
//! constants and object parameters), Lepton 16-bit PNG/TIFF and raw, radiometric TIFF
//! ([`read_thermal_file`], [`decode_thermal`]).

mod file;
pub mod flir;

pub use file::{ThermalFileKind, ThermalImage, ThermalOptions, decode_thermal, read_thermal_file};
