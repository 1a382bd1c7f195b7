//! Command-line arguments. The doc comments are the `--help` text.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use mrtmap_pipeline::calibration::CalibrateArgs;
use mrtmap_pipeline::demo::DemoArgs;
use mrtmap_pipeline::export::{DEFAULT_MAX_POINTS, ExportFormat, ExportSource};
use mrtmap_pipeline::maps::SceneSource;
use mrtmap_pipeline::parse::{parse_facing, parse_grid, parse_mark, parse_point, parse_sun};
use mrtmap_pipeline::settings::{PointFrame, Quantity};
use mrtmap_pipeline::simulation::SimulateArgs;
use mrtmap_pipeline::source::SourceOptions;
use mrtmap_pipeline::thermal_image::ThermalReading;
use mrtmap_pipeline::validation::GlobeFormulaChoice;
use mrtmap_pipeline::{FuseFlags, MrtFlags, SegmentFlags, TrackFlags};

/// Map the mean radiant temperature (MRT) of a room.
///
/// MRT is the uniform surrounding temperature that would exchange as much radiant heat with a
/// person as the real room does (ISO 7726). mrtmap computes it from a radiant scene: the room's
/// surfaces with their temperatures (`scene.json`), exactly from solid angles or by Monte Carlo
/// ray tracing, at points or over a grid at head height.
#[derive(Debug, Parser)]
#[command(name = "mrtmap", version, about, long_about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Map MRT over a grid at a height above the floor: CSV, PNG and SVG heatmaps, summary.
    Map(MapArgs),
    /// MRT at points, with the view-factor table behind each.
    Mrt(MrtArgs),
    /// Convert a black-globe reading to MRT (ISO 7726, or mixed convection), or back.
    Globe(GlobeArgs),
    /// Operative temperature and PMV/PPD (ISO 7730) from air and mean radiant temperature.
    Comfort(ComfortArgs),
    /// The sun on a person behind glass (SolarCal, ASHRAE 55 Appendix C): the effective radiant
    /// field and the rise ΔMRT of the mean radiant temperature.
    SolarGain(SolarGainArgs),
    /// Write the built-in example scene (an office with a cold window) as scene.json.
    ExampleScene(ExampleSceneArgs),
    /// Simulate a handheld thermal + RGB-D scan of a room, with exact truth.
    Simulate(SimulateArgs),
    /// List the preset rooms, or print one as TOML to start your own.
    Rooms(RoomsArgs),
    /// Track the camera of a recording that has colour and depth but no poses (trajectory.txt,
    /// track.json; with groundtruth.txt, the trajectory error).
    Track(TrackArgs),
    /// Fuse a recording into a 3D thermal point cloud (cloud.ply, fusion.json).
    Fuse(FuseArgs),
    /// Segment a fused cloud into the room's surfaces and thermal features: scene.json.
    Segment(SegmentArgs),
    /// The whole pipeline on a recording: fuse, segment, MRT maps and points, report.html.
    Run(RunArgs),
    /// On site: is a scan good enough for a ±0.2 K map, and if not, where to point the camera (a
    /// coarse run: walls never seen, each surface's coverage, the unseen areas that matter most).
    Coverage(CoverageArgs),
    /// On site, live: follow a recording as it is written, serve a page showing the room filling
    /// in, what is missing and when it is enough; then make the full run.
    Live(LiveArgs),
    /// Write a finished recording into a new folder at its own pace, as a recorder would (to try
    /// `mrtmap live` without a rig).
    Replay(ReplayArgs),
    /// Simulate the office scan, run the pipeline and compare with the truth (the seed paper's table).
    Demo(DemoArgs),
    /// Compare a map with black-globe readings (ISO 7726 and mixed convection).
    Validate(ValidateArgs),
    /// Calibrate the rig from checkerboard image pairs: thermal and colour intrinsics, and the
    /// thermal camera's pose (rig.toml).
    Calibrate(CalibrateArgs),
    /// Render synthetic checkerboard pairs (colour + 160×120 thermal) with exact truth.
    SimulateBoard(SimulateBoardArgs),
    /// Read one thermal image (FLIR R-JPEG/FFF, Lepton PNG/TIFF/raw, radiometric TIFF): metadata,
    /// temperature statistics, CSV/PNG export.
    Thermal(ThermalArgs),
    /// List what a scan source holds: streams, counts, rates, time span, and what a scan lacks.
    Inspect(InspectArgs),
    /// Convert a ROS 1 bag, ROS 2 bag (MCAP or SQLite), MCAP file or RTAB-Map database to the
    /// recording layout (or a recording folder to a bag, MCAP, .db3 or RTAB-Map-layout file).
    Convert(ConvertArgs),
    /// Export a measured room to Honeybee (HBJSON), gbXML, glTF binary (with the thermal cloud)
    /// or Radiance, with its measured temperatures.
    Export(ExportArgs),
}

/// `mrtmap export`.
#[derive(Debug, Args)]
#[command(after_long_help = "Examples:
  mrtmap export out/ --out room.hbjson          a run's room for Honeybee (format from the extension)
  mrtmap export out/ --to gltf --out room.glb   with the thermal cloud, for Blender or a web viewer
  mrtmap export scene.json --out room.xml       gbXML 6.01
  mrtmap export model.hbjson --temperatures t.csv --out model.rad")]
pub struct ExportArgs {
    #[command(flatten)]
    pub source: ExportSource,
    /// The format: hbjson, gbxml, gltf (binary .glb) or rad; by default from --out's extension.
    #[arg(long, value_enum)]
    pub to: Option<ExportFormat>,
    /// The file to write.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Most thermal-cloud points in a glTF (evenly thinned; 0 leaves the cloud out).
    #[arg(long, default_value_t = DEFAULT_MAX_POINTS)]
    pub max_points: usize,
}

/// `mrtmap inspect`.
#[derive(Debug, Args)]
#[command(after_long_help = "Examples:
  mrtmap inspect scan.bag
  mrtmap inspect rosbag2_2026_11_22-10_00_00/     (ROS 2 bag folder: .mcap or .db3, split or not)
  mrtmap inspect rtabmap.db --json
  mrtmap inspect scan/")]
pub struct InspectArgs {
    /// A recording folder, ROS 1 bag, MCAP file, ROS 2 bag (folder or .db3) or RTAB-Map database.
    pub source: PathBuf,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Reading options.
    #[command(flatten)]
    pub src: SourceOptions,
}

/// Container of `convert`'s output when it is a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CompressionArg {
    /// Stored.
    None,
    /// bzip2 (bags) / zstd (MCAP).
    Bz2,
    /// LZ4.
    Lz4,
}

/// `mrtmap convert`.
#[derive(Debug, Args)]
#[command(after_long_help = "Examples:
  mrtmap convert scan.bag --out scan --rig rig.toml
  mrtmap convert scan.mcap --out scan --thermal-topic /lepton/image_raw
  mrtmap convert rtabmap.db --out scan --thermal thermal.bag --rig rig.toml
  mrtmap convert scan --out scan.bag            (recording folder → RealSense-style bag)
  mrtmap convert scan --out scan.db             (recording folder → RTAB-Map-layout database)
  mrtmap convert scan --out scan.db3            (recording folder → ROS 2 bag, SQLite storage)

A bag (ROS 1, or a ROS 2 folder of .mcap or .db3 files), MCAP file or database becomes the recording layout (depth/, thermal/, rgb/, lists,
trajectory.txt, rig.toml, source.json saying what was chosen). A recording folder with an output
ending in .bag, .mcap or .db3 becomes a RealSense-style bag, MCAP or rosbag2 SQLite file, and one
ending in .db a
database in RTAB-Map's layout with a node per colour frame (to test readers and pipelines).")]
pub struct ConvertArgs {
    /// The source.
    pub source: PathBuf,
    /// Output folder (or .bag / .mcap / .db3 / .db file for a recording folder).
    #[arg(long, value_name = "OUT")]
    pub out: PathBuf,
    /// Chunk compression when writing a bag or MCAP file.
    #[arg(long, value_enum, default_value_t = CompressionArg::Lz4)]
    pub compression: CompressionArg,
    /// Schema when writing an RTAB-Map-layout database (.db): current (0.23, RVL depth,
    /// optimised poses) or legacy (0.20, PNG depth, odometry only).
    #[arg(long, value_enum, default_value_t = mrtmap_pipeline::source::Schema::Current)]
    pub schema: mrtmap_pipeline::source::Schema,
    /// Reading options.
    #[command(flatten)]
    pub src: SourceOptions,
}

/// `mrtmap thermal`.
#[derive(Debug, Args)]
#[command(after_long_help = "Examples:
  mrtmap thermal IR_0001.jpg --csv ir.csv --png ir.png
  mrtmap thermal frame.fff --emissivity 0.92 --reflected 21.5 --distance 2
  mrtmap thermal lepton.y16 --centikelvin thermal.png
  mrtmap thermal duo.tiff --scale 0.04

FLIR files are converted with their own Planck constants, emissivity, reflected temperature,
distance and atmosphere (the options replace the file's values). 16-bit PNG/TIFF/raw values are
kelvin × scale: 0.01 (Lepton TLinear centikelvin) unless --scale says otherwise or only 0.04
gives plausible temperatures (it says so). Float TIFFs are °C, or K when their median is above 150.")]
pub struct ThermalArgs {
    /// The thermal image.
    pub file: PathBuf,
    /// Write the temperatures (°C, one image row per line) as CSV.
    #[arg(long, value_name = "OUT")]
    pub csv: Option<PathBuf>,
    /// Write a colour-mapped PNG (iron palette, min to max).
    #[arg(long, value_name = "OUT")]
    pub png: Option<PathBuf>,
    /// Write a 16-bit centikelvin PNG (the recording layout's thermal encoding).
    #[arg(long, value_name = "OUT")]
    pub centikelvin: Option<PathBuf>,
    /// Print the metadata and statistics as JSON.
    #[arg(long)]
    pub json: bool,
    /// How to read the file.
    #[command(flatten)]
    pub reading: ThermalReading,
}

/// `mrtmap simulate-board`.
#[derive(Debug, Args)]
pub struct SimulateBoardArgs {
    /// Output folder: rgb/, thermal/ (16-bit centikelvin), truth.json.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Number of pairs.
    #[arg(long, default_value_t = 20)]
    pub pairs: usize,
    /// Of those, pairs with the board partly out of view.
    #[arg(long, default_value_t = 3)]
    pub partial: usize,
    /// Random seed.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// Thermal blur, Gaussian σ in thermal pixels.
    #[arg(long, default_value_t = 0.7)]
    pub blur_px: f64,
    /// Thermal noise (K, standard deviation).
    #[arg(long, default_value_t = 0.05)]
    pub noise_k: f64,
}

/// `mrtmap run`.
#[derive(Debug, Args)]
#[command(after_long_help = mrtmap_pipeline::settings::PROJECT_EXAMPLE)]
pub struct RunArgs {
    /// The recording: a folder in the recording layout (docs/recording.md), a ROS 1 bag, an MCAP
    /// file, a ROS 2 bag (folder or .db3) or an RTAB-Map database (converted into OUT/recording
    /// first).
    pub recording: PathBuf,
    /// How to read a bag, MCAP file or database.
    #[command(flatten)]
    pub src: SourceOptions,
    /// Output folder: fuse/, segment/, map-H.HHm/ per height, report.html, run.json.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// A project file (TOML) with what is set once per scan; every key is listed below. Flags
    /// override it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Rerun every stage even when its inputs have not changed.
    #[arg(long)]
    pub force: bool,
    /// Grid nodes as COLSxROWS ([map] grid).
    #[arg(long, value_parser = parse_grid)]
    pub grid: Option<(usize, usize)>,
    /// Map height above the floor (m), repeatable ([map] heights_m).
    #[arg(long = "height")]
    pub heights: Vec<f64>,
    /// What to map besides MRT, repeatable ([map] quantities): mrt_seated, mrt_standing,
    /// asymmetry, operative, pmv, ppd (the person and air from [comfort] and [air]).
    #[arg(long = "quantity", value_enum)]
    pub quantities: Vec<Quantity>,
    /// Margin from the walls (m) ([map] margin_m).
    #[arg(long = "margin-m")]
    pub margin_m: Option<f64>,
    /// A named point NAME=X,Y,Z, repeatable ([[points]]): in the room frame (x, y along the floor
    /// from the origin corner, z above the floor), or in the scan's frame with --frame scan.
    #[arg(long = "mark", value_name = "NAME=X,Y,Z", value_parser = parse_mark)]
    pub marks: Vec<(String, Vec<f64>)>,
    /// The frame of --mark: room (default) or scan (the frame of trajectory.txt).
    #[arg(long, value_enum, default_value_t = PointFrame::Room)]
    pub frame: PointFrame,
    /// The floor corner at the room frame's origin, as numbered on the report's map ([room]
    /// origin_corner); by default the start of the longest wall with the room at x, y ≥ 0.
    #[arg(long, value_name = "N")]
    pub origin_corner: Option<usize>,
    /// `[track]`'s flags.
    #[command(flatten)]
    pub track: TrackFlags,
    /// `[fuse]`'s flags.
    #[command(flatten)]
    pub fuse: FuseFlags,
    /// `[segment]`'s flags.
    #[command(flatten)]
    pub segment: SegmentFlags,
    /// Air temperature for the report (°C) ([air] temperature_c).
    #[arg(long, allow_negative_numbers = true)]
    pub air_c: Option<f64>,
}

/// `mrtmap coverage`.
#[derive(Debug, Args)]
pub struct CoverageArgs {
    /// The recording (any source `mrtmap run` takes).
    pub recording: PathBuf,
    /// How to read a bag, MCAP file or database.
    #[command(flatten)]
    pub src: SourceOptions,
    /// Keep the coarse run here (fuse/, segment/, map-1.10m/); by default it goes to a temporary
    /// folder that is removed.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// A project file (TOML): its settings, made coarse.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// The map's target (K, 2σ): the scan is good enough when what it did not see keeps the map
    /// within it.
    #[arg(
        long = "target-k",
        default_value_t = 0.2,
        allow_negative_numbers = true
    )]
    pub target_k: f64,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `mrtmap live`.
#[derive(Debug, Args)]
pub struct LiveArgs {
    /// The recording folder a recorder is writing: rig.toml from the start, the lists growing by
    /// appended lines, each line's file written before the line.
    pub recording: PathBuf,
    /// Where to serve the page (ADDRESS:PORT; port 0 picks a free port, printed at the start).
    #[arg(long, value_name = "ADDR", default_value = "127.0.0.1:8080")]
    pub serve: String,
    /// Output folder of the full run made when following ends (what `mrtmap run` makes).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// A project file (TOML): the full run's settings (the live preview makes them coarse).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// The map's target (K, 2σ) the verdict is given against.
    #[arg(
        long = "target-k",
        default_value_t = 0.2,
        allow_negative_numbers = true
    )]
    pub target_k: f64,
    /// Stop following once the recording has not grown for this many seconds (default: follow
    /// until Ctrl-C); then make the full run and exit.
    #[arg(
        long = "exit-when-idle",
        value_name = "SECONDS",
        allow_negative_numbers = true
    )]
    pub exit_when_idle: Option<f64>,
}

/// `mrtmap replay`.
#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// The finished recording folder.
    pub recording: PathBuf,
    /// The new folder to write it into (must not exist yet, or be empty).
    #[arg(long, value_name = "DIR")]
    pub into: PathBuf,
    /// How many times the scan's own pace (1: as recorded).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub speed: f64,
}

/// `mrtmap validate`.
#[derive(Debug, Args)]
pub struct ValidateArgs {
    /// A folder with scene.json (or a `mrtmap run` output, with segment/scene.json).
    #[arg(long, value_name = "DIR")]
    pub map: PathBuf,
    /// Globe readings: CSV with the columns label,x,y,z,tg_c,ta_c,va_m_s,diameter_m,emissivity (°C,
    /// m/s, m; x, y, z in the room frame of scene.json, or the scan's with --frame scan). With a
    /// header the columns may come in any order and others (time, notes) are ignored; `#` starts a
    /// comment line.
    #[arg(long, value_name = "FILE")]
    pub globe: PathBuf,
    /// The frame of the globes' x, y, z: room (scene.json's, default) or scan.
    #[arg(long, value_enum, default_value_t = PointFrame::Room)]
    pub frame: PointFrame,
    /// Readings (by label, comma-separated) that fix the map's temperature level instead of
    /// reference readings: every temperature is shifted so that the map matches their ISO 7726
    /// MRT; they are then shown but not judged, and the others are compared.
    #[arg(long, value_name = "LABEL,…", value_delimiter = ',')]
    pub calibrate_with: Vec<String>,
    /// A project.toml whose `[sun]` places the sun: a globe whose centre the beam reaches through
    /// a window is flagged "in sun" and not judged (its reading includes short-wave radiation the
    /// long-wave map does not).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Where to write validation.csv and validation.json (default: the map folder).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

/// `mrtmap segment`.
#[derive(Debug, Args)]
pub struct SegmentArgs {
    /// The output folder of `mrtmap fuse` (cloud.ply, poses.txt).
    pub fused: PathBuf,
    /// A recording with instance masks (masks.txt; see docs/simulator.md for the format) to label
    /// the features by a majority vote over frames. Without it, features get rule labels.
    #[arg(long, value_name = "DIR")]
    pub masks: Option<PathBuf>,
    /// The recording that was fused: its thermal frames are cast onto the room model found, so
    /// that what the depth camera did not see (glass, dark surfaces, dropouts) takes the thermal
    /// camera's temperatures (needs the fusion's frames.json; --masks implies it).
    #[arg(long, value_name = "DIR")]
    pub recording: Option<PathBuf>,
    /// Output folder for scene.json, segments.ply and segment.json.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// A project file (TOML): its [segment], [room], [emissivity], [[references]] and [mrt]
    /// apply, as in `mrtmap run`; flags override it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// `[segment]`'s flags.
    #[command(flatten)]
    pub section: SegmentFlags,
    /// The floor corner at the room frame's origin, as numbered in segment.json's floor_corners;
    /// by default the start of the longest wall with the room at x, y ≥ 0 ([room] origin_corner).
    #[arg(long, value_name = "N")]
    pub origin_corner: Option<usize>,
    /// Contact-thermometer readings (label,x,y,z,temperature_c[,std_k][,frame]; x, y, z in the
    /// room frame unless the frame column says scan, the frame of trajectory.txt) that fix the
    /// temperatures' absolute level (one: offset; two or more on different temperatures: gain
    /// too). Default: the recording's references.csv, as in `mrtmap run`; --config's
    /// [[references]] are added either way.
    #[arg(long, value_name = "CSV")]
    pub references: Option<PathBuf>,
}

/// `mrtmap fuse`.
#[derive(Debug, Args)]
pub struct FuseArgs {
    /// The recording: a folder in the recording layout (docs/recording.md), a ROS 1 bag, an MCAP
    /// file, a ROS 2 bag (folder or .db3) or an RTAB-Map database (converted into OUT/recording
    /// first).
    pub recording: PathBuf,
    /// How to read a bag, MCAP file or database.
    #[command(flatten)]
    pub src: SourceOptions,
    /// Output folder for cloud.ply, fusion.json and the refined trajectory.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// A project file (TOML): its [fuse] applies, as in `mrtmap run`; flags override it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// `[fuse]`'s flags.
    #[command(flatten)]
    pub fuse: FuseFlags,
}

/// `mrtmap track`.
#[derive(Debug, Args)]
pub struct TrackArgs {
    /// The recording folder (docs/recording.md) with colour frames (rgb.txt) and depth.
    pub recording: PathBuf,
    /// Output folder for trajectory.txt and track.json.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// A project file (TOML): its [track] applies, as in `mrtmap run`; flags override it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// `[track]`'s flags.
    #[command(flatten)]
    pub track: TrackFlags,
}

/// `mrtmap rooms`.
#[derive(Debug, Args)]
pub struct RoomsArgs {
    /// Print this preset as TOML.
    pub name: Option<String>,
}

/// `mrtmap map`.
#[derive(Debug, Args)]
#[command(allow_negative_numbers = true)]
pub struct MapArgs {
    #[command(flatten)]
    pub scene: SceneSource,
    /// Height of the map above the floor (m); 1.1 m is seated head height, 1.7 m standing.
    /// Default: --config's first [map] heights_m, else 1.1.
    #[arg(long)]
    pub height: Option<f64>,
    /// Grid nodes as COLSxROWS over the floor's bounding rectangle (nodes outside the floor are
    /// left out). Default: --config's [map] grid, else 20x20.
    #[arg(long, value_parser = parse_grid)]
    pub grid: Option<(usize, usize)>,
    /// Distance kept from the floor outline (m). Default: --config's [map] margin_m, else 0.1.
    #[arg(long = "margin-m")]
    pub margin_m: Option<f64>,
    /// A point to mark and report, NAME=U,V in map coordinates (x,y for a z-up scene) or
    /// NAME=X,Y,Z in scene coordinates. Repeatable.
    #[arg(long = "mark", value_name = "NAME=U,V", allow_hyphen_values = true, value_parser = parse_mark)]
    pub marks: Vec<(String, Vec<f64>)>,
    #[command(flatten)]
    pub method: MrtFlags,
    /// What else to map, repeatable: a person's MRT (mrt_seated, mrt_standing), the MRT with the
    /// sun (mrt_sun, needs --config's [sun]), radiant asymmetry, operative temperature, PMV, PPD;
    /// the person and the air come from --config's [comfort] and [air], and with [sun] operative,
    /// PMV and PPD include the sun. Written as QUANTITY.png/.svg/.csv and comfort.json beside the
    /// MRT map.
    #[arg(long = "quantity", value_enum)]
    pub quantities: Vec<Quantity>,
    /// A project.toml: its [map], [mrt], [comfort], [air] and [sun] apply, each flag given
    /// overriding its key.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Air temperature (°C) for operative temperature, PMV and PPD ([air] temperature_c).
    #[arg(long, allow_negative_numbers = true)]
    pub air_c: Option<f64>,
    /// Output folder for mrt_grid.csv, mrt_map.png, mrt_map.svg and summary.json.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// `mrtmap mrt`.
#[derive(Debug, Args)]
#[command(allow_negative_numbers = true)]
pub struct MrtArgs {
    #[command(flatten)]
    pub scene: SceneSource,
    /// A point X,Y,Z (m) in the scene file's frame: for a scanned room, its room frame (x, y along
    /// the floor from the origin corner, z above the floor). Repeatable.
    #[arg(long = "at", value_name = "X,Y,Z", required = true, allow_hyphen_values = true, value_parser = parse_point)]
    pub at: Vec<[f64; 3]>,
    /// The frame of --at: room (the scene file's, default) or scan (the scan's world frame; needs
    /// a scene written by segmentation, which records where the room sits in the scan).
    #[arg(long, value_enum, default_value_t = PointFrame::Room)]
    pub frame: PointFrame,
    #[command(flatten)]
    pub method: MrtFlags,
    /// The MRT of a person instead of a small sphere: --at is the body centre (0.6 m above the
    /// floor seated, 1.0 m standing); angle factors from the projected-area factors of a seated or
    /// standing body.
    #[arg(long, value_enum)]
    pub person: Option<mrtmap_pipeline::points::Posture>,
    /// Which way the person faces, degrees from +x towards +y (0 = +x, 90 = +y); without it,
    /// any way (fp averaged over azimuth).
    #[arg(long, allow_negative_numbers = true, requires = "person", value_parser = parse_facing)]
    pub facing: Option<f64>,
    /// Also the plane radiant temperatures of a small element's six faces and the radiant
    /// asymmetries (vertical, and the worst horizontal pair every 15°) with ISO 7730's PD and category.
    #[arg(long)]
    pub plane: bool,
    /// The sun on the person through the scene's glazing (features labelled window, skylight,
    /// roof light, glazed or glass door, curtain wall, glazing or glass): its altitude and its azimuth in the room's frame like --facing (0 = the sun
    /// beyond the +x side), degrees. Adds SolarCal's ΔMRT beside the MRT, with the sky-vault view
    /// fraction and the share of the body in the beam traced in the scene. Needs --facing, --dni
    /// and --transmittance.
    #[arg(long, value_name = "ALT,AZ", allow_hyphen_values = true, value_parser = parse_sun, requires_all = ["facing", "dni", "transmittance"])]
    pub sun: Option<[f64; 2]>,
    /// Direct normal irradiance outside (W/m²), with --sun.
    #[arg(
        long,
        value_name = "W_M2",
        allow_negative_numbers = true,
        requires = "sun"
    )]
    pub dni: Option<f64>,
    /// The windows' total solar transmittance with their shades (0…1), with --sun.
    #[arg(
        long,
        value_name = "T",
        allow_negative_numbers = true,
        requires = "sun"
    )]
    pub transmittance: Option<f64>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// A project file (TOML): its [mrt] applies, and its [sun] when --sun is not given; flags
    /// override it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
}

/// `mrtmap comfort`.
#[derive(Debug, Args)]
#[command(allow_negative_numbers = true)]
pub struct ComfortArgs {
    /// Air temperature (°C).
    #[arg(long, allow_negative_numbers = true, required_unless_present = "csv")]
    pub ta: Option<f64>,
    /// Mean radiant temperature (°C).
    #[arg(long, allow_negative_numbers = true, required_unless_present = "csv")]
    pub tr: Option<f64>,
    /// Air speed (m/s); PMV uses the relative air speed v + 0.3 (met − 1) above 1 met.
    #[arg(long, default_value_t = 0.1)]
    pub v: f64,
    /// Relative humidity (%).
    #[arg(long, default_value_t = 50.0)]
    pub rh: f64,
    /// Metabolic rate (met).
    #[arg(long, default_value_t = 1.2)]
    pub met: f64,
    /// Clothing insulation (clo).
    #[arg(long, default_value_t = 0.7)]
    pub clo: f64,
    /// Many at once: a CSV with the columns ta,tr,v,rh,met,clo (header first); prints a CSV with
    /// operative_c, pmv, ppd added.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["ta", "tr"])]
    pub csv: Option<PathBuf>,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

/// `mrtmap solar-gain`: SolarCal as pythermalcomfort's `solar_gain`.
#[derive(Debug, Args)]
#[command(allow_negative_numbers = true)]
pub struct SolarGainArgs {
    /// Solar altitude above the horizon (degrees, 0…90).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub altitude: f64,
    /// The sun's horizontal angle from the person's front, SHARP (degrees, 0…180: 0 the sun
    /// ahead, 90 beside, 180 behind).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub sharp: f64,
    /// Direct normal irradiance outside (W/m²; ASHRAE 55 Table C-2 gives 200…1000).
    #[arg(long, value_name = "W_M2", allow_negative_numbers = true)]
    pub dni: f64,
    /// Total solar transmittance of the glazing with its shades (0…1).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub transmittance: f64,
    /// Fraction of the sky vault the person sees through the windows (0…1; for a window
    /// w × h straight ahead at distance d, atan(h/2d)° · atan(w/2d)° / 16200).
    #[arg(long, value_name = "F", allow_negative_numbers = true)]
    pub f_svv: f64,
    /// Fraction of the body's projected area in the beam (0…1; ASHRAE 55 Figure C2-1).
    #[arg(long, value_name = "F", allow_negative_numbers = true)]
    pub f_bes: f64,
    /// The person's short-wave absorptivity (0…1; 0.57 to 0.84 by skin and clothing).
    #[arg(long, value_name = "A", allow_negative_numbers = true, default_value_t = mrtmap_pipeline::comfort::DEFAULT_ASW)]
    pub asw: f64,
    /// Posture ("sitting" is taken for seated).
    #[arg(long, value_enum, default_value_t = mrtmap_pipeline::comfort::SolarPosture::Seated)]
    pub posture: mrtmap_pipeline::comfort::SolarPosture,
    /// Short-wave reflectance of the floor (0…1).
    #[arg(long, value_name = "R", allow_negative_numbers = true, default_value_t = mrtmap_pipeline::comfort::DEFAULT_FLOOR_REFLECTANCE)]
    pub floor_reflectance: f64,
    /// Print JSON (the inputs, erf_w_m2 and delta_mrt_k).
    #[arg(long)]
    pub json: bool,
}

/// `mrtmap globe`.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("reading").required(true).args(["tg", "tr"])))]
#[command(allow_negative_numbers = true)]
pub struct GlobeArgs {
    /// Globe temperature (°C): converts to MRT.
    #[arg(long, allow_negative_numbers = true)]
    pub tg: Option<f64>,
    /// Mean radiant temperature (°C): gives the temperature the globe would read (the inverse).
    #[arg(long, allow_negative_numbers = true)]
    pub tr: Option<f64>,
    /// Air temperature (°C).
    #[arg(long, allow_negative_numbers = true)]
    pub ta: f64,
    /// Air speed (m/s).
    #[arg(long, default_value_t = 0.0)]
    pub va: f64,
    /// Globe diameter (m).
    #[arg(long, default_value_t = 0.15)]
    pub diameter: f64,
    /// Globe emissivity.
    #[arg(long, default_value_t = 0.95)]
    pub emissivity: f64,
    /// Formula.
    #[arg(long, value_enum, default_value_t = GlobeFormulaChoice::Iso)]
    pub method: GlobeFormulaChoice,
    /// Convection regime for the ISO formulas.
    #[arg(long, value_enum, default_value_t = mrtmap_pipeline::validation::Convection::Larger)]
    pub convection: mrtmap_pipeline::validation::Convection,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

/// `mrtmap example-scene`.
#[derive(Debug, Args)]
pub struct ExampleSceneArgs {
    /// Write to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
}
