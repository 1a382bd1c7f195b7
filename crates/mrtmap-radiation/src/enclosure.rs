//! Scenes in true surface temperatures: solved as the grey enclosure they are before any MRT.
//!
//! A scene that says `"temperatures": "surface"` gives what a contact thermometer reads. A person
//! exchanges radiation with the radiosities, which a camera reads: each element's own emission
//! and what it reflects of the others'. [`solve_enclosure`] finds them (the radiosity method,
//! one node per surface background and feature, as the simulator's grey truth), and [`engine`]
//! is the one way to an MRT engine for any scene: [`MrtEngine::new`] refuses a scene whose
//! surface temperatures are not solved, so no path weights them by emissivity instead.

use mrtmap_physics::Temperature;

use crate::engine::{Method, MrtEngine, MrtError};
use crate::grey::{GreyElement, irradiances, radiant_temperature};
use crate::scene::{RadiantScene, TemperatureKind};

/// An MRT engine for `scene` with `method`: on the scene itself, or, when it gives true surface
/// temperatures of grey elements, on its radiosities ([`solve_enclosure`]).
pub fn engine(scene: &RadiantScene, method: Method) -> Result<MrtEngine<'_>, MrtError> {
    if needs_enclosure_solve(scene) {
        MrtEngine::new_owned(solve_enclosure(scene, method)?, method)
    } else {
        MrtEngine::new(scene, method)
    }
}

/// Rounds of the radiosity iteration of [`solve_enclosure`]: each shrinks the error by 1 − ε
/// (0.16 at most, glass), as the simulator's grey truth takes them.
pub const ENCLOSURE_ROUNDS: usize = 3;

/// Whether `scene` gives the true surface temperatures ("temperatures": "surface") of elements
/// that are not black: its MRT then needs the radiosities, which [`solve_enclosure`] finds.
pub fn needs_enclosure_solve(scene: &RadiantScene) -> bool {
    scene.gives_grey_surface_temperatures()
}

/// A scene in true surface temperatures solved as the grey enclosure it is: each surface (its
/// background) and feature leaves the radiosity J = εσT⁴ + (1 − ε)σT_irr⁴, its irradiance
/// σT_irr⁴ coming from the others' radiosities ([`irradiances`] with `method`: the T⁴ mean of the
/// plane radiant temperatures at up to nine points on it), iterated [`ENCLOSURE_ROUNDS`] times
/// from J = σT⁴. The answer is a scene of radiant temperatures (what a camera would read), each
/// element keeping its true temperature as its surface temperature, and its ± from the true
/// temperature's (× ε(T/T_r)³) and the irradiance's sampling error (× (1 − ε)(T_irr/T_r)³).
/// A raster's texels take their surface's irradiance. Furniture keeps its temperature (its
/// emissivity weights it as before).
///
/// The weighted average Tr⁴ = ΣεFT⁴ / ΣεF is right only where every surface reflects the
/// point's own MRT; near cold glass, which reflects the room, it reads low (0.2–0.4 K in the
/// grey office).
pub fn solve_enclosure(scene: &RadiantScene, method: Method) -> Result<RadiantScene, MrtError> {
    let given = scene.to_file();
    let to_radiant = |irr: Option<&[GreyElement]>| -> Result<RadiantScene, MrtError> {
        let mut file = given.clone();
        file.temperatures = Some(TemperatureKind::Radiant);
        let mut k = 0;
        for (si, s) in file.surfaces.iter_mut().enumerate() {
            let src = &scene.surfaces[si];
            let el = irr.and_then(|e| e.get(k));
            k += 1;
            let (t, std) = radiosity(src.temperature, src.temperature_std_k, src.emissivity, el);
            s.temperature_c = t.celsius();
            s.temperature_std_k = std;
            s.surface_temperature_c = Some(src.temperature.celsius());
            s.surface_temperature_std_k = Some(src.temperature_std_k.unwrap_or(0.0));
            if let Some(r) = &mut s.raster {
                for v in r.temperature_c.iter_mut().flatten() {
                    let (t, _) = radiosity(Temperature::from_celsius(*v), None, src.emissivity, el);
                    *v = t.celsius();
                }
            }
            for (fi, f) in s.features.iter_mut().enumerate() {
                let srcf = &src.features[fi];
                let el = irr.and_then(|e| e.get(k));
                k += 1;
                let (t, std) = radiosity(
                    srcf.temperature,
                    srcf.temperature_std_k,
                    srcf.emissivity,
                    el,
                );
                f.temperature_c = t.celsius();
                f.temperature_std_k = std;
                f.surface_temperature_c = Some(srcf.temperature.celsius());
                f.surface_temperature_std_k = Some(srcf.temperature_std_k.unwrap_or(0.0));
            }
        }
        RadiantScene::new(&file).map_err(|e| MrtError::EnclosureSolve(e.to_string()))
    };
    let mut radiant = to_radiant(None)?;
    for _ in 0..ENCLOSURE_ROUNDS {
        let engine = MrtEngine::new(&radiant, method)?;
        let elements = irradiances(&engine);
        radiant = to_radiant(Some(&elements))?;
    }
    Ok(radiant)
}

/// The radiosity temperature of an element at `t` (± `std_k`) with emissivity `e` and the
/// irradiance of `el` (none yet: `t` itself), with its ±.
fn radiosity(
    t: Temperature,
    std_k: Option<f64>,
    e: f64,
    el: Option<&GreyElement>,
) -> (Temperature, Option<f64>) {
    let Some((irr, irr_std)) = el.and_then(|el| el.irradiance) else {
        return (t, std_k);
    };
    let j = radiant_temperature(t, irr, e);
    let (tk, ik, jk) = (t.kelvin(), irr.kelvin(), j.kelvin());
    let from_t = std_k.map(|s| e * (tk / jk).powi(3) * s);
    let from_irr = (1.0 - e) * (ik / jk).powi(3) * irr_std;
    let std = from_t.map(|a| (a * a + from_irr * from_irr).sqrt());
    (j, std)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn c(x: f64) -> Temperature {
        Temperature::from_celsius(x)
    }

    #[test]
    fn radiant_scenes_ignore_emissivity_in_the_mrt_and_surface_ones_weight_by_it() {
        use mrtmap_geometry::nalgebra::Point3;
        let mut scene = crate::example_office();
        let p = Point3::new(2.0, 1.5, 1.1);
        let black = engine(&scene, Method::Exact)
            .unwrap()
            .at(&p, 0)
            .unwrap()
            .mrt;
        for s in &mut scene.surfaces {
            for f in &mut s.features {
                f.emissivity = 0.5;
            }
        }
        let legacy = engine(&scene, Method::Exact)
            .unwrap()
            .at(&p, 0)
            .unwrap()
            .mrt;
        assert!((legacy.kelvin() - black.kelvin()).abs() > 0.01);
        scene.temperatures = Some(TemperatureKind::Radiant);
        let radiant = engine(&scene, Method::Exact)
            .unwrap()
            .at(&p, 0)
            .unwrap()
            .mrt;
        assert!((radiant.kelvin() - black.kelvin()).abs() < 1e-12);
        scene.temperatures = Some(TemperatureKind::Surface);
        let surface = engine(&scene, Method::Exact)
            .unwrap()
            .at(&p, 0)
            .unwrap()
            .mrt;
        // True surface temperatures are solved as the grey enclosure (no longer weighted by ε):
        // the answer is the MRT of the radiosities, each between its element's own temperature
        // and what it receives.
        let solved = solve_enclosure(&scene, Method::Exact).unwrap();
        assert_eq!(solved.temperatures, Some(TemperatureKind::Radiant));
        let direct = MrtEngine::new(&solved, Method::Exact)
            .unwrap()
            .at(&p, 0)
            .unwrap()
            .mrt;
        assert!((surface.kelvin() - direct.kelvin()).abs() < 1e-12);
        let solved_engine = MrtEngine::new(&solved, Method::Exact).unwrap();
        let irr = irradiances(&solved_engine);
        for el in irr.iter().filter(|e| e.feature.is_some()) {
            let (given, radiant) = (
                &scene.surfaces[el.surface].features[el.feature.unwrap()],
                &solved.surfaces[el.surface].features[el.feature.unwrap()],
            );
            let t_irr = el.irradiance.unwrap().0.kelvin();
            let (t, j) = (given.temperature.kelvin(), radiant.temperature.kelvin());
            assert!(
                (j - t) * (t_irr - t) >= -1e-9 && (j - t).abs() <= (t_irr - t).abs() + 0.05,
                "{}: T {t} J {j} T_irr {t_irr}",
                given.id
            );
            assert_eq!(radiant.surface_temperature.unwrap().0, given.temperature);
        }
    }

    /// In a room at one temperature the radiosities are that temperature whatever the
    /// emissivities: the solved MRT is it. The plain engine refuses the unsolved scene.
    #[test]
    fn a_uniform_grey_enclosure_radiates_its_temperature() {
        use mrtmap_geometry::nalgebra::Point3;
        let mut scene = crate::example_office();
        scene.temperatures = Some(TemperatureKind::Surface);
        for s in &mut scene.surfaces {
            s.emissivity = 0.9;
            s.temperature = c(21.0);
            for f in &mut s.features {
                f.emissivity = 0.84;
                f.temperature = c(21.0);
            }
        }
        assert!(needs_enclosure_solve(&scene));
        let m = engine(&scene, Method::Exact)
            .unwrap()
            .at(&Point3::new(1.0, 1.0, 1.1), 0)
            .unwrap()
            .mrt;
        assert!((m.celsius() - 21.0).abs() < 1e-6, "{}", m.celsius());
        let e = MrtEngine::new(&scene, Method::Exact)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("surface temperatures"), "{e}");
    }
}
