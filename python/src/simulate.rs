//! `simulate`: a material on a scene (a scene file, or an experiment's
//! specimen) -> simulated heights with the membrane models, through the
//! library's sweep as `bulge simulate` (quasi-static) calls it.

use std::path::PathBuf;

use bulge::Refusal;
use bulge::experiment::Experiment;
use bulge::material::Material;
use bulge::pipeline::{
    DynamicRequest, SceneOverrides, StaticError, experiment_scene, simulate_dynamic,
    simulate_static,
};
use bulge::sim::dynamics::Integrator;
use bulge::sim::scene::Scene;
use bulge::sim::solve::{Options, Solver};
use bulge::sim::springs::HeightModel;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use super::stages::choice;
use super::{Counter, bad, chain, failed, to_toml};

/// The settings of a dynamic run (`bulge simulate --dynamic`).
#[derive(FromPyObject)]
pub struct Dynamic {
    /// Integrator names.
    #[pyo3(item)]
    integrators: Vec<String>,
    /// Time step, s.
    #[pyo3(item)]
    dt: Option<f64>,
    /// Simulated time, s.
    #[pyo3(item)]
    t_end: Option<f64>,
    /// Fraction of critical damping.
    #[pyo3(item)]
    damping: f64,
    /// `critical` or `sudhamani-merriliance`.
    #[pyo3(item)]
    damping_law: String,
    /// `substep` or `refuse`.
    #[pyo3(item)]
    step_policy: String,
    /// XPBD iterations per step.
    #[pyo3(item)]
    xpbd_iterations: usize,
}

/// `simulated.csv`, the meridian profile (with `profile=True`; the time
/// histories of a dynamic run), the notes
/// on the mesh, the warnings and the pressures without an equilibrium.
type SimulateResult = (
    Py<PyBytes>,
    Option<Py<PyBytes>>,
    Vec<String>,
    Vec<String>,
    Vec<String>,
);

/// `bulge simulate` (quasi-static): `material_path` or `material` (a dict
/// as material.toml reads), on the scene file `scene` or the specimen of
/// `experiment`; the other keywords as its flags. `progress(done, total)`
/// is called once per model and pressure.
#[pyfunction]
#[pyo3(signature = (material_path=None, material=None, experiment=None, scene=None,
    pressures=None, models=vec!["tp".to_string()], solvers=vec!["newton".to_string()],
    tolerance=1e-8, max_iterations=None, edge_length=None, nodes=None, accuracy=None,
    max_nodes=None, full=false, profile=false, density=None, progress=None, dynamic=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    py: Python<'_>,
    material_path: Option<PathBuf>,
    material: Option<Bound<'_, PyDict>>,
    experiment: Option<PathBuf>,
    scene: Option<PathBuf>,
    pressures: Option<Vec<f64>>,
    models: Vec<String>,
    solvers: Vec<String>,
    tolerance: f64,
    max_iterations: Option<usize>,
    edge_length: Option<f64>,
    nodes: Option<usize>,
    accuracy: Option<f64>,
    max_nodes: Option<usize>,
    full: bool,
    profile: bool,
    density: Option<f64>,
    progress: Option<PyObject>,
    dynamic: Option<Dynamic>,
) -> PyResult<SimulateResult> {
    let models: Vec<HeightModel> = models
        .iter()
        .map(|m| {
            m.parse::<HeightModel>()
                .map_err(|e| bad(format!("model={m:?}: {e}")))
        })
        .collect::<PyResult<_>>()?;
    let solvers: Vec<Solver> = solvers
        .iter()
        .map(|s| choice::<Solver>("solver", s))
        .collect::<PyResult<_>>()?;
    if models.is_empty() || solvers.is_empty() {
        return Err(bad(
            "model and solver each need at least one name (e.g. model=\"tp,axisym\")".into(),
        ));
    }
    let axisym = models.contains(&HeightModel::Axisym);
    let integrators: Vec<Integrator> = match &dynamic {
        Some(d) => d
            .integrators
            .iter()
            .map(|i| {
                Integrator::ALL
                    .into_iter()
                    .find(|x| x.name() == i.trim())
                    .ok_or_else(|| {
                        bad(format!(
                            "integrator={i:?} is not one of explicit-euler, symplectic-euler, verlet, implicit-euler, xpbd"
                        ))
                    })
            })
            .collect::<PyResult<_>>()?,
        None => Vec::new(),
    };
    if profile && !axisym {
        return Err(bad(
            "profile=True returns the axisym meridian: add axisym to model".into(),
        ));
    }
    let mut opts = Options {
        tolerance,
        ..Options::default()
    };
    if let Some(n) = max_iterations {
        opts.newton_iterations = n;
        opts.dr_steps = n;
    }
    opts.validate()
        .map_err(|e| bad(format!("tolerance / max_iterations: {e}")))?;
    let table = match &material {
        Some(d) => match to_toml("material", d.as_any())? {
            toml::Value::Table(t) => Some(t),
            _ => unreachable!("a dict is a table"),
        },
        None => None,
    };
    let overrides = SceneOverrides {
        pressures,
        edge_length,
        nodes,
        accuracy,
        full,
        max_nodes,
        density,
    };
    let out = py.allow_threads(move || {
        let material = match (material_path, table) {
            (Some(p), _) => Some(Material::read(&p).map_err(|e| (true, chain(&e)))?),
            (None, Some(t)) => Some(
                Material::from_table(&t)
                    .map_err(|e| (true, format!("<material dict>: {}", chain(&e))))?,
            ),
            (None, None) => None,
        };
        let mut notes = Vec::new();
        let (mut sc, origin) = if let Some(path) = &scene {
            let mut s = Scene::read(path).map_err(|e| (true, chain(&e)))?;
            if let Some(m) = material {
                s.material = m;
            }
            (s, path.display().to_string())
        } else if let Some(path) = &experiment {
            let e = Experiment::read(path).map_err(|e| (true, chain(&e)))?;
            let m = material.ok_or((
                true,
                "experiment needs material (a dict as bulge.fit returns it, or a material.toml path)"
                    .to_string(),
            ))?;
            if overrides.pressures.is_none() {
                return Err((
                    true,
                    "experiment needs pressures (Pa, e.g. [5000, 7300, 8940])".to_string(),
                ));
            }
            let (s, note) = experiment_scene(&e, path, m).map_err(|m| (true, m))?;
            notes.extend(note);
            (s, path.display().to_string())
        } else {
            return Err((
                true,
                "give scene= (a scene file) or experiment= with material= and pressures=".into(),
            ));
        };
        overrides.apply(&mut sc);
        sc.validate(sc.needs_pressures())
            .map_err(|m| (true, format!("{origin}: {m}")))?;
        let springs = models.iter().filter(|m| **m != HeightModel::Axisym).count();
        let total = match &dynamic {
            Some(_) => models.len() * integrators.len() * sc.pressures_to_solve().len(),
            None => (springs * solvers.len() + usize::from(axisym)) * sc.pressures_to_solve().len(),
        };
        let counter = Counter::new(progress, total);
        let tick = || counter.tick();
        if let Some(d) = &dynamic {
            let req = DynamicRequest {
                scene: &sc,
                models: &models,
                integrators: &integrators,
                dt: d.dt,
                t_end: d.t_end,
                damping: d.damping,
                damping_law: &d.damping_law,
                step_policy: &d.step_policy,
                xpbd_iterations: d.xpbd_iterations,
            };
            let out = simulate_dynamic(&req, &tick).map_err(|e| (e.bad, e.message))?;
            notes.extend(out.notes);
            return Ok((
                out.csv.into_bytes(),
                Some(out.trace.into_bytes()),
                notes,
                out.warnings,
                out.failures,
            ));
        }
        let out = simulate_static(&sc, &models, &solvers, opts, profile, &mut |_, _| {}, &tick)
            .map_err(|e| match e {
                StaticError::Mesh(m) => (true, format!("accuracy or the mesh: {m}")),
                e => (e.is_bad_input(), chain(&e)),
            })?;
        notes.extend(out.notes);
        Ok((
            out.simulated.into_bytes(),
            out.profile.map(|p| p.into_bytes()),
            notes,
            out.warnings,
            out.failures,
        ))
    });
    match out {
        Ok((csv, prof, notes, warnings, failures)) => Ok((
            PyBytes::new(py, &csv).unbind(),
            prof.map(|p| PyBytes::new(py, &p).unbind()),
            notes,
            warnings,
            failures,
        )),
        Err((true, m)) => Err(bad(m)),
        Err((false, m)) => Err(failed(m)),
    }
}
