//! Exports: Honeybee, gbXML, glTF and Radiance written and read back.
#![allow(clippy::unwrap_used)]

mod export;
