//! One module per subcommand: flags → one library call → print. Commands do not call each other;
//! what they share for output is in `crate::output`.

mod calibrate;
mod comfort;
mod convert;
mod coverage;
mod demo;
mod example_scene;
mod export;
mod fuse;
mod globe;
mod inspect;
mod live;
mod map;
mod mrt;
mod rooms;
mod run;
mod segment;
mod simulate;
mod simulate_board;
mod solar_gain;
mod thermal;
mod track;
mod validate;

use crate::cli::{Cli, Command};

/// Runs a parsed command line.
pub fn dispatch(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Map(a) => map::run(&a),
        Command::Mrt(a) => mrt::run(&a),
        Command::Globe(a) => globe::run(&a),
        Command::Comfort(a) => comfort::run(&a),
        Command::SolarGain(a) => solar_gain::run(&a),
        Command::ExampleScene(a) => example_scene::run(&a),
        Command::Simulate(a) => simulate::run(&a),
        Command::Rooms(a) => rooms::run(&a),
        Command::Track(a) => track::run(&a),
        Command::Fuse(a) => fuse::run(&a),
        Command::Segment(a) => segment::run(&a),
        Command::Run(a) => run::run(&a),
        Command::Coverage(a) => coverage::run(&a),
        Command::Live(a) => live::run(&a),
        Command::Replay(a) => live::replay(&a),
        Command::Demo(a) => demo::run(&a),
        Command::Validate(a) => validate::run(&a),
        Command::Calibrate(a) => calibrate::run(&a),
        Command::SimulateBoard(a) => simulate_board::run(&a),
        Command::Thermal(a) => thermal::run(&a),
        Command::Inspect(a) => inspect::run(&a),
        Command::Convert(a) => convert::run(&a),
        Command::Export(a) => export::run(&a),
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use clap::Parser;
    use mrtmap_pipeline::Project;

    use crate::cli::{Cli, Command};

    /// The project a command line resolves to (the commands that take settings).
    fn project(args: &[&str]) -> Project {
        let cli = Cli::try_parse_from(std::iter::once("mrtmap").chain(args.iter().copied()))
            .unwrap_or_else(|e| panic!("{args:?}: {e}"));
        match cli.command {
            Command::Run(a) => super::run::settings(&a),
            Command::Fuse(a) => super::fuse::settings(&a),
            Command::Segment(a) => super::segment::settings(&a),
            Command::Track(a) => super::track::settings(&a),
            Command::Map(a) => super::map::settings(&a),
            Command::Mrt(a) => super::mrt::settings(&a),
            _ => panic!("{args:?}: not a command with settings"),
        }
        .unwrap_or_else(|e| panic!("{args:?}: {e}"))
    }

    /// Issue 61: every flag of every command that takes settings gives the project the key it
    /// names gives in a project.toml, and every such command reads --config.
    #[test]
    fn each_flag_of_each_command_is_its_project_key() {
        let dir = tempfile::tempdir().unwrap();
        let heads: [(&str, &[&str]); 6] = [
            ("run", &["run", "rec", "--out", "o"]),
            ("fuse", &["fuse", "rec", "--out", "o"]),
            ("segment", &["segment", "fused", "--out", "o"]),
            ("track", &["track", "rec", "--out", "o"]),
            ("map", &["map", "--scene", "s.json", "--out", "o"]),
            ("mrt", &["mrt", "--scene", "s.json", "--at", "1,1,1"]),
        ];
        // (commands, the flags, the project.toml that says the same)
        let cases: &[(&[&str], &[&str], &str)] = &[
            (
                &["run", "fuse"],
                &["--voxel-m", "0.05"],
                "[fuse]\nvoxel_m = 0.05",
            ),
            (&["run", "fuse"], &["--icp", "off"], "[fuse]\nicp = false"),
            (
                &["run", "fuse"],
                &["--sync-tolerance-ms", "30"],
                "[fuse]\nsync_tolerance_ms = 30.0",
            ),
            (
                &["run", "fuse"],
                &["--depth-stride", "2"],
                "[fuse]\ndepth_stride = 2",
            ),
            (
                &["run", "fuse"],
                &["--self-calibrate", "off"],
                "[fuse]\nself_calibrate = false",
            ),
            (
                &["run", "fuse"],
                &["--time-offset", "-70"],
                "[fuse]\ntime_offset = \"-70\"",
            ),
            (
                &["run", "segment"],
                &["--feature-threshold-k", "0.5"],
                "[segment]\nfeature_threshold_k = 0.5",
            ),
            (
                &["run", "segment"],
                &["--feature-min-area-m2", "0.1"],
                "[segment]\nfeature_min_area_m2 = 0.1",
            ),
            (
                &["run", "segment"],
                &["--raster-m", "0"],
                "[segment]\nraster_m = 0.0",
            ),
            (
                &["run", "segment"],
                &["--no-masks"],
                "[segment]\nmasks = false",
            ),
            (
                &["run", "segment"],
                &["--origin-corner", "2"],
                "[room]\norigin_corner = 2",
            ),
            (
                &["run", "track"],
                &["--no-loops"],
                "[track]\nloop_closure = false",
            ),
            (&["run", "track"], &["--no-imu"], "[track]\nuse_imu = false"),
            (
                &["run", "track"],
                &["--fast-threshold", "9"],
                "[track]\nfast_threshold = 9",
            ),
            (&["run", "map"], &["--grid", "7x5"], "[map]\ngrid = [7, 5]"),
            (
                &["run", "map"],
                &["--height", "1.7"],
                "[map]\nheights_m = [1.7]",
            ),
            (
                &["run", "map"],
                &["--margin-m", "0.2"],
                "[map]\nmargin_m = 0.2",
            ),
            (
                &["run", "map"],
                &["--air-c", "22"],
                "[air]\ntemperature_c = 22.0",
            ),
            (
                &["run", "map"],
                &["--quantity", "mrt_seated"],
                "[map]\nquantities = [\"mrt_seated\"]",
            ),
            (&["map", "mrt"], &["--rays", "1000"], "[mrt]\nrays = 1000"),
            (&["map", "mrt"], &["--seed", "7"], "[mrt]\nseed = 7"),
            (
                &["map", "mrt"],
                &["--method", "exact"],
                "[mrt]\nmethod = \"exact\"",
            ),
            (
                &["map", "mrt"],
                &["--replicates", "4"],
                "[mrt]\nreplicates = 4",
            ),
            (
                &["map", "mrt"],
                &["--placement-std-m", "0.02"],
                "[mrt]\nplacement_std_m = 0.02",
            ),
            (
                &["map", "mrt"],
                &["--allow-open"],
                "[mrt]\nallow_open = true",
            ),
        ];
        let mut checked = 0;
        for (k, (commands, flags, toml)) in cases.iter().enumerate() {
            let file = dir.path().join(format!("p{k}.toml"));
            std::fs::write(&file, toml).unwrap();
            let file = file.to_str().unwrap();
            for c in *commands {
                let head = heads.iter().find(|(n, _)| n == c).unwrap().1;
                let by_flag = project(&[head, flags].concat());
                let by_key = project(&[head, &["--config", file]].concat());
                assert_eq!(by_flag, by_key, "{c} {flags:?} against {toml}");
                assert_ne!(by_flag, Project::default(), "{c} {flags:?} changed nothing");
                checked += 1;
            }
        }
        assert_eq!(checked, 2 * cases.len());
    }
}
