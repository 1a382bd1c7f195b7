//! `[mrt]` (and the flags of `map` and `mrt`): how view factors are computed.

use mrtmap_geometry::sampling::DirectionSet;
use mrtmap_radiation::{Method, MonteCarlo, MrtEngine, RadiantScene};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// How view factors are computed: one choice for flags (`--method`) and `[mrt] method`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum MethodChoice {
    /// Exact solid angles where valid; Monte Carlo with occluders or where surfaces hide each
    /// other (non-convex rooms).
    #[default]
    Auto,
    /// Exact solid angles (Van Oosterom–Strackee), features subtracted from their host.
    Exact,
    /// Monte Carlo ray tracing against a BVH (handles occluders and non-convex rooms).
    Montecarlo,
}

/// Monte Carlo direction sets: one choice for `--directions` and `[mrt] directions`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum DirectionChoice {
    /// Randomly rotated spherical Fibonacci lattices (converges faster).
    #[default]
    Fibonacci,
    /// Independent uniform random directions.
    Random,
}

impl From<DirectionChoice> for DirectionSet {
    fn from(d: DirectionChoice) -> Self {
        match d {
            DirectionChoice::Fibonacci => DirectionSet::Fibonacci,
            DirectionChoice::Random => DirectionSet::Random,
        }
    }
}

/// `[mrt]`: the view-factor method (its flags: [`crate::MrtFlags`]; the defaults those of
/// [`Default`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MrtSection {
    /// View-factor method: exact solid angles where valid and Monte Carlo with occluders or where
    /// surfaces hide each other (auto), exact solid angles only (exact), or Monte Carlo ray
    /// tracing (montecarlo).
    pub method: MethodChoice,
    /// Monte Carlo: rays per point.
    pub rays: usize,
    /// Monte Carlo: random seed (results are reproducible from it).
    pub seed: u64,
    /// Monte Carlo: direction set (randomly rotated spherical Fibonacci lattices converge faster
    /// than independent random directions).
    pub directions: DirectionChoice,
    /// Monte Carlo: independent replicates the standard errors come from.
    pub replicates: usize,
    /// Answer at points the scene does not enclose (a missing wall, floor or ceiling leaves part
    /// of the view empty: ΣF short of 1) instead of refusing them; ΣF is printed with each point.
    pub allow_open: bool,
    /// How well a point is placed relative to the room's surfaces (m, one standard deviation): the
    /// MRT's gradient times it joins the MRT's ± (near a cold window it dominates; not yet a
    /// person's or a plane's); 0 leaves it out.
    pub placement_std_m: f64,
}

impl Default for MrtSection {
    fn default() -> Self {
        let mc = MonteCarlo::default();
        Self {
            method: MethodChoice::Auto,
            rays: mc.rays,
            seed: mc.seed,
            directions: DirectionChoice::Fibonacci,
            replicates: mc.replicates,
            allow_open: false,
            placement_std_m: 0.01,
        }
    }
}

impl MrtSection {
    /// The method for `scene`: `auto` is Monte Carlo when the scene has occluders (exact solid
    /// angles cannot see them), else exact with Monte Carlo where surfaces hide each other.
    pub fn method(&self, scene: &RadiantScene) -> Result<Method> {
        self.check()?;
        let mc = MonteCarlo {
            rays: self.rays,
            seed: self.seed,
            directions: self.directions.into(),
            replicates: self.replicates,
        };
        Ok(match self.method {
            MethodChoice::Exact => Method::Exact,
            MethodChoice::Montecarlo => Method::MonteCarlo(mc),
            MethodChoice::Auto if scene.occluders.is_empty() => Method::Auto(mc),
            MethodChoice::Auto => Method::MonteCarlo(mc),
        })
    }

    /// Settings that need no scene: the placement uncertainty and the ray count (checked before a
    /// run's fusion, not after it).
    pub fn check(&self) -> Result<()> {
        if self.rays == 0 {
            return Err(Error::setting(
                "--rays 0 ([mrt] rays)",
                "is too few: at least 1 ray per point is needed",
            ));
        }
        if self.method != MethodChoice::Exact && self.replicates < 2 {
            return Err(Error::setting(
                format!("--replicates {} ([mrt] replicates)", self.replicates),
                "is too few: the standard error needs at least 2 independent replicates",
            ));
        }
        if self.rays > MAX_RAYS {
            return Err(Error::setting(
                format!("--rays {} ([mrt] rays)", self.rays),
                format!(
                    "is more than the {MAX_RAYS} rays per point allowed (each ray holds about 42 bytes while a point is answered: 1e8 rays took 4.2 GB); 20000 give about ±0.01 K"
                ),
            ));
        }
        if !(self.placement_std_m.is_finite() && (0.0..=1.0).contains(&self.placement_std_m)) {
            return Err(Error::setting(
                format!(
                    "--placement-std-m {} ([mrt] placement_std_m)",
                    self.placement_std_m
                ),
                "must be between 0 and 1 m",
            ));
        }
        Ok(())
    }

    /// The engine for `scene` with these settings (its method, and whether open scenes are
    /// answered).
    pub fn engine<'a>(&self, scene: &'a RadiantScene) -> Result<MrtEngine<'a>> {
        self.check()?;
        Ok(
            mrtmap_radiation::enclosure::engine(scene, self.method(scene)?)?
                .allow_open(self.allow_open)
                .with_placement_std(self.placement_std_m),
        )
    }
}

/// The most Monte Carlo rays per point a setting may ask for: 10 million (about 420 MB while a
/// point is answered); issue 54 found 2e9 running out of memory and 1e15 aborting Python.
pub const MAX_RAYS: usize = 10_000_000;
