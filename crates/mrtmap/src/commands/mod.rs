//! One module per subcommand, and the settings they share.

mod calibrate;
mod demo;
mod example_scene;
mod fuse;
mod globe;
mod map;
mod mrt;
mod rtabmap;
mod run;
mod segment;
mod simulate;
mod source;
mod thermal;
mod validate;

use anyhow::bail;
use mrtmap_geometry::sampling::DirectionSet;
use mrtmap_radiation::{Method, MonteCarlo, RadiantScene, example_office};

use crate::cli::{Cli, Command, DirectionsArg, MethodArg, MethodArgs, SceneArgs};

/// Runs a parsed command line.
pub fn dispatch(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Map(a) => map::run(&a),
        Command::Mrt(a) => mrt::run(&a),
        Command::Globe(a) => globe::run(&a),
        Command::ExampleScene(a) => example_scene::run(&a),
        Command::Simulate(a) => simulate::run(&a),
        Command::Rooms(a) => simulate::rooms(&a),
        Command::Fuse(a) => fuse::run(&a),
        Command::Segment(a) => segment::run(&a),
        Command::Run(a) => run::run(&a),
        Command::Demo(a) => demo::run(&a),
        Command::Validate(a) => validate::run(&a),
        Command::Calibrate(a) => calibrate::run(&a),
        Command::SimulateBoard(a) => calibrate::simulate_board(&a),
        Command::Thermal(a) => thermal::run(&a),
        Command::Inspect(a) => source::inspect(&a),
        Command::Convert(a) => source::convert(&a),
    }
}

/// The scene the user named, or the built-in example; the string says which.
pub(crate) fn load_scene(args: &SceneArgs) -> anyhow::Result<(RadiantScene, String)> {
    Ok(match &args.scene {
        Some(p) => (RadiantScene::load(p)?, p.display().to_string()),
        None => (example_office(), "the built-in example office".to_string()),
    })
}

/// The method from flags: `auto` picks exact unless the scene has occluders.
pub(crate) fn resolve_method(args: &MethodArgs, scene: &RadiantScene) -> anyhow::Result<Method> {
    let mc = || MonteCarlo {
        rays: args.rays,
        seed: args.seed,
        directions: match args.directions {
            DirectionsArg::Fibonacci => DirectionSet::Fibonacci,
            DirectionsArg::Random => DirectionSet::Random,
        },
        replicates: args.replicates,
    };
    if args.rays == 0 {
        bail!("--rays must be at least 1");
    }
    Ok(match args.method {
        MethodArg::Exact => Method::Exact,
        MethodArg::Montecarlo => Method::MonteCarlo(mc()),
        MethodArg::Auto if scene.occluders.is_empty() => Method::Auto(mc()),
        MethodArg::Auto => Method::MonteCarlo(mc()),
    })
}

/// A line describing a method for people.
pub fn describe_method(method: &Method, engine: Option<&str>) -> String {
    match method {
        Method::Exact => "exact view factors (solid angles)".to_string(),
        Method::Auto(mc) => format!(
            "exact view factors (solid angles), Monte Carlo ({} rays) where surfaces hide each other",
            mc.rays
        ),
        Method::MonteCarlo(mc) => format!(
            "Monte Carlo view factors ({} rays per point, {:?} directions in {} replicates, seed {}{})",
            mc.rays,
            mc.directions,
            mc.replicates,
            mc.seed,
            engine.map(|e| format!(", {e}")).unwrap_or_default()
        )
        .replace("Fibonacci", "Fibonacci-lattice")
        .replace("Random", "random"),
    }
}
