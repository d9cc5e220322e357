//! The scene of `bulge simulate`: a scene file, or an experiment's specimen
//! with a material, and the flags that override it.

use std::path::Path;

use anyhow::anyhow;

use super::Args;
use bulge::experiment::Experiment;
use bulge::material::Material;
use bulge::sim::scene::{MeshSize, Scene};

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
        if (m.poisson - e.specimen.poisson).abs() > 1e-12 {
            eprintln!(
                "note: the material's poisson = {} is used; the specimen says {}",
                m.poisson, e.specimen.poisson
            );
        }
        if args.pressures.is_none() {
            return Err(anyhow!(
                "--experiment needs --pressures (Pa, comma-separated, e.g. 5000,7300,8940)"
            ));
        }
        // Every key of the experiment that shapes the membrane is honoured
        // or refused: a dome height still to be found has no value here.
        if e.prebulge_fit {
            return Err(anyhow!(
                "{}: prebulge_height_m = \"fit\" is found from the heights by bulge run (its notes and material.toml give the value); bulge simulate needs the number: write it in [specimen], e.g. prebulge_height_m = 0.00375",
                exp.display()
            ));
        }
        Scene::from_window(&e.specimen, &e.window, m, Vec::new())
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
    if let Some(p) = &args.pressures {
        scene.pressures_pa = p.clone();
    }
    if let Some(h) = args.edge_length {
        scene.mesh.size = Some(MeshSize::EdgeLength(h));
    }
    if let Some(n) = args.nodes {
        scene.mesh.size = Some(MeshSize::Nodes(n));
    }
    if let Some(a) = args.accuracy {
        scene.mesh.size = Some(MeshSize::Accuracy(a));
    }
    if args.full {
        scene.mesh.symmetry = false;
    }
    scene.mesh.max_nodes = args.max_nodes.unwrap_or(scene.mesh.max_nodes);
    if let Some(d) = args.density {
        scene.density_kg_m3 = d;
    }
    Ok(args
        .scene
        .as_deref()
        .or(args.experiment.as_deref())
        .unwrap_or(Path::new("command line"))
        .display()
        .to_string())
}
