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
