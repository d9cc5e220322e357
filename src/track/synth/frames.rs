//! The bubble to be drawn: its silhouette at each pressure, from the exact
//! axisymmetric solution on a circular opening, or from the membrane model
//! on an elliptical window (its section through the long axis).

use super::{Silhouette, SynthFrame, axisym_frame};
use crate::experiment::{Specimen, Window};
use crate::material::Material;

/// Why the bubble could not be drawn at a pressure: the law has no
/// equilibrium there (past its limit point) or the window's mesh failed.
#[derive(Debug, thiserror::Error)]
pub enum FramesError {
    /// The axisymmetric solution at a pressure.
    #[error("the bubble at {pressure_pa} Pa: {source}")]
    Axisym {
        /// The pressure, Pa.
        pressure_pa: f64,
        /// Why.
        #[source]
        source: crate::axisym::AxisymError,
    },
    /// The membrane model on the window.
    #[error("the bubble on the window{}: {source}", at.map_or(String::new(), |p| format!(" at {p} Pa")))]
    Window {
        /// The pressure without an equilibrium (none: the mesh failed).
        at: Option<f64>,
        /// Why.
        #[source]
        source: crate::sim::SimError,
    },
}

impl crate::Refusal for FramesError {
    /// The material, the specimen and the pressures are the user's: a law
    /// without an equilibrium at a pressure asked for is refused input.
    fn is_bad_input(&self) -> bool {
        true
    }
}

/// `n` pressures from `p_min` to `p_max` in equal steps (`p_max` alone for
/// one).
pub fn pressure_steps(p_min: f64, p_max: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            if n == 1 {
                p_max
            } else {
                p_min + (p_max - p_min) * k as f64 / (n - 1) as f64
            }
        })
        .collect()
}

/// The silhouettes of `material`'s bubble on `specimen` through `window` at
/// each of `pressures`, in order; `tick` after each one solved.
pub fn bubble_frames(
    material: &Material,
    specimen: &Specimen,
    window: &Window,
    pressures: &[f64],
    tick: &dyn Fn(),
) -> Result<Vec<SynthFrame>, FramesError> {
    if !window.is_circle() {
        return window_frames(specimen, window, material, pressures, tick);
    }
    pressures
        .iter()
        .map(|&p| {
            let frame =
                axisym_frame(material, specimen, p, p).map_err(|source| FramesError::Axisym {
                    pressure_pa: p,
                    source,
                });
            tick();
            frame
        })
        .collect()
}

/// The frames of a non-circular window: the membrane model swept over the
/// pressures, and at each its section through the long axis (the nodes on
/// `y = 0`, `x >= 0`, which stay on that mirror plane), pole first.
fn window_frames(
    specimen: &Specimen,
    window: &Window,
    material: &Material,
    pressures: &[f64],
    tick: &dyn Fn(),
) -> Result<Vec<SynthFrame>, FramesError> {
    use crate::sim::scene::Scene;
    use crate::sim::{SceneSolver, SpringModel};
    let mesh_failed = |source| FramesError::Window { at: None, source };
    let scene = Scene::from_window(specimen, window, material.clone(), pressures.to_vec());
    let mesh = scene.build_mesh().map_err(mesh_failed)?;
    let section: Vec<usize> = (0..mesh.nodes.len())
        .filter(|&i| mesh.nodes[i].y.abs() < 1e-12 && mesh.nodes[i].x >= 0.0)
        .collect();
    let mut s = SceneSolver::on_mesh(&scene, mesh, SpringModel::Membrane).map_err(mesh_failed)?;
    let mut frames = Vec::with_capacity(pressures.len());
    let done = s.sweep(pressures, |solver, q| {
        let x = solver.positions();
        let mut pts: Vec<(f64, f64)> = section.iter().map(|&i| (x[i].x, x[i].z)).collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        frames.push(SynthFrame {
            pressure_pa: q.pressure_pa,
            silhouette: Silhouette {
                rho_m: pts.iter().map(|p| p.0).collect(),
                z_m: pts.iter().map(|p| p.1).collect(),
            },
        });
        tick();
    });
    if let Err((_, stop)) = done {
        return Err(FramesError::Window {
            at: Some(stop.pressure_pa),
            source: stop.error,
        });
    }
    Ok(frames)
}
