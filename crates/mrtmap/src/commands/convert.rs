//! `mrtmap convert`: a bag, MCAP file, ROS 2 bag or RTAB-Map database → the recording layout, or a
//! recording folder → one of those.

use mrtmap_pipeline::Error;
use mrtmap_pipeline::source::{Compression, convert_any, plan_lines};

use crate::cli::{CompressionArg, ConvertArgs};
use crate::output::print_lines;

pub fn run(a: &ConvertArgs) -> anyhow::Result<()> {
    let compression = match a.compression {
        CompressionArg::None => Compression::None,
        CompressionArg::Bz2 => Compression::Bz2,
        CompressionArg::Lz4 => Compression::Lz4,
    };
    match convert_any(&a.source, &a.out, compression, a.schema, &a.src) {
        Ok(lines) => {
            print_lines(lines);
            Ok(())
        }
        Err(e) => {
            if let Error::NotAScan {
                plan: Some(plan), ..
            } = &e
            {
                print_lines(plan_lines(plan));
            }
            Err(e.into())
        }
    }
}
