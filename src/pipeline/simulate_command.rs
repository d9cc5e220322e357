//! `bulge simulate` (quasi-static) in memory: the scene of an experiment's
//! specimen, the settings that override a scene, and the sweep with what it
//! writes and says, for the command line and the Python package alike.

use std::path::Path;

use crate::experiment::Experiment;
use crate::io::CsvOut;
use crate::material::Material;
use crate::setting::Setting;
use crate::sim::scene::{MeshSize, Scene};
use crate::sim::solve::{self, Solver};
use crate::sim::springs::{HeightModel, SpringModel};
use crate::sim::{SceneSolver, SimError, SweepPoint};

use super::*;

/// What may replace a scene's own settings (the flags of `bulge simulate`,
/// the keywords of the Python function).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneOverrides {
    /// Pressures in Pa, solved in this order.
    pub pressures: Option<Vec<f64>>,
    /// Mesh: target edge length, m.
    pub edge_length: Option<f64>,
    /// Mesh: about this many solved nodes.
    pub nodes: Option<usize>,
    /// Mesh: the relative height error wanted (a disc).
    pub accuracy: Option<f64>,
    /// Mesh the whole scene instead of its symmetric part.
    pub full: bool,
    /// Largest mesh, nodes.
    pub max_nodes: Option<usize>,
    /// Density, kg/m^3.
    pub density: Option<f64>,
}

impl SceneOverrides {
    /// Replaces the scene's settings with those given.
    pub fn apply(&self, scene: &mut Scene) {
        if let Some(p) = &self.pressures {
            scene.pressures_pa = p.clone();
        }
        if let Some(h) = self.edge_length {
            scene.mesh.size = Some(MeshSize::EdgeLength(h));
        }
        if let Some(n) = self.nodes {
            scene.mesh.size = Some(MeshSize::Nodes(n));
        }
        if let Some(a) = self.accuracy {
            scene.mesh.size = Some(MeshSize::Accuracy(a));
        }
        if self.full {
            scene.mesh.symmetry = false;
        }
        scene.mesh.max_nodes = self.max_nodes.unwrap_or(scene.mesh.max_nodes);
        if let Some(d) = self.density {
            scene.density_kg_m3 = d;
        }
    }
}

/// The scene of the experiment `exp` (read from `path`): its specimen
/// through its window, with `material`, and a note when the material's
/// Poisson ratio is not the specimen's. A dome height still to be found
/// (`prebulge_height_m = "fit"`) has no value here and is refused.
pub fn experiment_scene(
    exp: &Experiment,
    path: &Path,
    material: Material,
) -> Result<(Scene, Option<String>), String> {
    if exp.prebulge_fit {
        return Err(format!(
            "{}: prebulge_height_m = \"fit\" is found from the heights by bulge run (its notes and material.toml give the value); bulge simulate needs the number: write it in [specimen], e.g. prebulge_height_m = 0.00375",
            path.display()
        ));
    }
    let note = ((material.poisson - exp.specimen.poisson).abs() > 1e-12).then(|| {
        format!(
            "note: the material's poisson = {} is used; the specimen says {}",
            material.poisson, exp.specimen.poisson
        )
    });
    let scene = Scene::from_window(&exp.specimen, &exp.window, material, Vec::new());
    Ok((scene, note))
}

/// A quasi-static sweep of a scene: what it wrote and said.
pub struct StaticOut {
    /// `simulated.csv` (with the scene's extra columns).
    pub simulated: CsvOut,
    /// The axisymmetric meridian at the last pressure solved, when asked.
    pub profile: Option<CsvOut>,
    /// The mesh (its sizing for an accuracy, its size and quality).
    pub notes: Vec<String>,
    /// Warnings: a mesh too coarse for a model, residuals at the round-off
    /// floor.
    pub warnings: Vec<String>,
    /// Each pressure without an equilibrium, with its model and solver.
    pub failures: Vec<String>,
    /// The runs themselves.
    pub runs: Vec<ModelRun>,
}

/// Why a sweep gave nothing.
#[derive(Debug, thiserror::Error)]
pub enum StaticError {
    /// The mesh could not be built or sized (the caller names its setting).
    #[error("{0}")]
    Mesh(String),
    /// A model or the reference could not be set up.
    #[error(transparent)]
    Run(#[from] PipelineError),
    /// The material's modulus is not positive at a strain the sweep reached:
    /// the material file's fault, not the solver's.
    #[error("{0}")]
    Material(String),
}

impl crate::Refusal for StaticError {
    fn is_bad_input(&self) -> bool {
        match self {
            StaticError::Run(e) => e.is_bad_input(),
            _ => true,
        }
    }
}

/// `bulge simulate` without `--dynamic`: every spring model of `models`
/// with every solver of `solvers` (the first sizes the mesh), and the exact
/// axisymmetric reference when `models` holds it, on `scene` at its
/// pressures; `profile` keeps the reference's meridian. `each` sees every
/// spring equilibrium, `tick` is called once per model and pressure.
pub fn simulate_static(
    scene: &Scene,
    models: &[HeightModel],
    solvers: &[Solver],
    options: solve::Options,
    profile: bool,
    each: &mut dyn FnMut(&SceneSolver, &SweepPoint),
    tick: &dyn Fn(),
) -> Result<StaticOut, StaticError> {
    let springs: Vec<SpringModel> = models
        .iter()
        .filter_map(|c| match c {
            HeightModel::Spring(m) => Some(*m),
            HeightModel::Axisym => None,
        })
        .collect();
    let axisym = models.contains(&HeightModel::Axisym);
    let first = solvers.first().copied().unwrap_or(Solver::Newton);
    let (mesh, sizing) = scene_mesh(scene, &springs, first, options)
        .map_err(|e| StaticError::Mesh(e.to_string()))?;
    let mut notes = Vec::new();
    if let (Some(s), Some(MeshSize::Accuracy(a))) = (sizing, scene.mesh.size) {
        notes.push(format!(
            "mesh sized for {} {a}: {} rings, estimated relative height error {:.2e} (Richardson: {} against {} rings)",
            Setting::Accuracy,
            s.rings,
            s.estimated_error,
            s.rings,
            s.coarse_rings
        ));
    }
    notes.push(describe_mesh(&mesh, scene));
    let mut warnings = Vec::new();
    for &model in &springs {
        for w in crate::sim::hard::mesh_warnings(&mesh, model, &scene.material, scene.thickness_m) {
            warnings.push(format!("({}): {w}", model.name()));
        }
    }
    let request = SceneRequest {
        models: springs,
        solvers: solvers.to_vec(),
        axisym,
        profile,
        options,
    };
    let out = simulate_scene(scene, &mesh, &request, each, tick)?;
    for r in &out.runs {
        if let Some(e @ SimError::NonPositiveModulus { .. }) = &r.stop
            && let Some(p) = r.points.iter().find(|p| p.outcome == Outcome::Failed)
        {
            return Err(StaticError::Material(format!(
                "{} / {} at {} Pa: {e}",
                r.model, r.solver, p.pressure_pa
            )));
        }
    }
    warnings.extend(
        out.runs
            .iter()
            .filter_map(|r| at_floor(r, options.tolerance)),
    );
    let failures = out
        .runs
        .iter()
        .flat_map(|r| r.failures().map(|n| format!("{n} ({})", r.solver)))
        .collect();
    Ok(StaticOut {
        simulated: simulated_csv_with(&out.runs, &scene.extra_columns()),
        profile: out.axisym_last.as_ref().map(crate::axisym::profile_csv),
        notes,
        warnings,
        failures,
        runs: out.runs,
    })
}

/// The mesh in one line: its size, the part solved, the triangles' angles
/// and edges.
pub fn describe_mesh(mesh: &crate::sim::mesh::Mesh, scene: &Scene) -> String {
    use crate::sim::scene::SceneKind;
    let q = mesh.quality();
    let part = match (scene.kind, mesh.symmetry_copies) {
        (SceneKind::Disc { .. }, 6) => " (60 degree sector with mirror planes)",
        (SceneKind::SphereSegment { .. }, _) => " (octant with three symmetry planes)",
        (SceneKind::Rectangle { .. }, 4) => " (quarter with mirror planes)",
        _ => "",
    };
    format!(
        "mesh: {} nodes, {} triangles{part}; angles {:.1}-{:.1} deg, non-acute {:.2} %, edges {:.3e}-{:.3e} m",
        mesh.nodes.len(),
        q.triangles,
        q.min_angle_deg,
        q.max_angle_deg,
        100.0 * q.non_acute_share,
        q.edge_range_m[0],
        q.edge_range_m[1]
    )
}

/// The warning for a run's pressures whose residual stopped above
/// `tolerance` at the round-off floor ([`Outcome::AtFloor`]), if any.
fn at_floor(run: &ModelRun, tolerance: f64) -> Option<String> {
    let at_floor: Vec<_> = run
        .points
        .iter()
        .filter(|p| p.outcome == Outcome::AtFloor)
        .collect();
    if at_floor.is_empty() {
        return None;
    }
    let worst = at_floor.iter().fold(0.0_f64, |a, p| a.max(p.residual));
    let ps: Vec<String> = at_floor.iter().map(|p| p.pressure_pa.to_string()).collect();
    Some(format!(
        "({} / {}): at {} Pa the residual (largest {worst:.2e} of the load) stopped above {} {tolerance:e}, at the round-off floor of double precision here (the membrane's internal forces dwarf the pressure's); those heights carry a relative error of about that size",
        run.model,
        run.solver,
        ps.join(", "),
        Setting::Tolerance
    ))
}
