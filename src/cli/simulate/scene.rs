//! The scene of `bulge simulate`: a scene file, or an experiment's specimen
//! with a material, and the flags that override it.

use std::path::Path;

use anyhow::anyhow;

use super::Args;
use bulge::experiment::Experiment;
use bulge::material::Material;
use bulge::pipeline::{SceneOverrides, experiment_scene};
use bulge::sim::scene::Scene;

/// The scene, validated: pressures required, except for a sheet with nodal
/// loads (solved under its loads alone when it has no pressure list, see
/// [`Scene::pressures_to_solve`]).
pub(super) fn build_scene(args: &Args) -> anyhow::Result<Scene> {
    let (scene, origin) = load_scene(args)?;
    scene
        .validate(scene.needs_pressures())
        .map_err(|m| anyhow!("{origin}: {m}"))?;
    Ok(scene)
}

/// Reads the scene (a scene file, or `--experiment` + `--material`), applies
/// the overriding flags, and returns it with the name of where it came from.
fn load_scene(args: &Args) -> anyhow::Result<(Scene, String)> {
    let material = match &args.material {
        Some(p) => Some(Material::read(p)?),
        None => None,
    };
    let mut scene = if let Some(path) = &args.scene {
        let mut s = Scene::read(path)?;
        if let Some(m) = material {
            s.material = m;
        }
        s
    } else if let Some(exp) = &args.experiment {
        let e = Experiment::read(exp)?;
        let m = material.ok_or_else(|| {
            anyhow!("--experiment needs --material material.toml (the material to simulate)")
        })?;
        if args.pressures.is_none() {
            return Err(anyhow!(
                "--experiment needs --pressures (Pa, comma-separated, e.g. 5000,7300,8940)"
            ));
        }
        let (scene, note) = experiment_scene(&e, exp, m).map_err(|m| anyhow!(m))?;
        if let Some(n) = note {
            eprintln!("{n}");
        }
        scene
    } else {
        return Err(anyhow!(
            "give a scene file (bulge simulate scene.toml) or --experiment FILE --material FILE --pressures P1,P2,..."
        ));
    };
    let origin = apply_overrides(&mut scene, args)?;
    Ok((scene, origin))
}

/// Applies the flags that override a scene (pressures, mesh size, symmetry,
/// density) and returns the name of where the scene came from, for messages.
fn apply_overrides(scene: &mut Scene, args: &Args) -> anyhow::Result<String> {
    SceneOverrides {
        pressures: args.pressures.clone(),
        edge_length: args.edge_length,
        nodes: args.nodes,
        accuracy: args.accuracy,
        full: args.full,
        max_nodes: args.max_nodes,
        density: args.density,
    }
    .apply(scene);
    Ok(args
        .scene
        .as_deref()
        .or(args.experiment.as_deref())
        .unwrap_or(Path::new("command line"))
        .display()
        .to_string())
}
