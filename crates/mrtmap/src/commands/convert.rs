//! `mrtmap convert`: a bag, MCAP file, ROS 2 bag or RTAB-Map database → the recording layout, or a
//! recording folder → one of those.

use mrtmap_pipeline::Error;
use mrtmap_pipeline::source::Compression;
use mrtmap_pipeline::source::Container;
use mrtmap_pipeline::source::{ContainerOut, convert, write_container};

use crate::cli::{CompressionArg, ConvertArgs};
use crate::output::print_lines;
use mrtmap_pipeline::source::plan_lines;

/// The container an output file name asks for, if any.
fn container_out(a: &ConvertArgs) -> Option<ContainerOut> {
    let ext = a
        .out
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let compression = match a.compression {
        CompressionArg::None => Compression::None,
        CompressionArg::Bz2 => Compression::Bz2,
        CompressionArg::Lz4 => Compression::Lz4,
    };
    Some(match ext.as_str() {
        "db" => ContainerOut::RtabMap(a.schema),
        "bag" => ContainerOut::Ros(Container::Bag, compression),
        "mcap" => ContainerOut::Ros(Container::Mcap, compression),
        "db3" => ContainerOut::Ros(Container::Db3, compression),
        _ => return None,
    })
}

pub fn run(a: &ConvertArgs) -> anyhow::Result<()> {
    if let Some(what) = container_out(a) {
        let w = write_container(&a.source, &a.out, what)?;
        let [d, t, c, p] = w.counts;
        match (w.nodes, what) {
            (Some(n), ContainerOut::RtabMap(schema)) => {
                outln!("wrote {} ({n} nodes, {schema:?} schema)", a.out.display());
            }
            _ => outln!(
                "wrote {} ({} bytes): {d} depth, {t} thermal, {c} colour frames, {p} poses",
                a.out.display(),
                w.bytes.unwrap_or(0)
            ),
        }
        return Ok(());
    }
    match convert(&a.source, &a.out, &a.src) {
        Ok(c) => {
            print_lines(c.lines());
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
