//! Parallel nodal forces (rayon), for meshes of 1e4 nodes and more.
//!
//! [`Membrane::forces`] scatters each triangle's (or spring's) force into its
//! nodes, which a parallel loop cannot do without races. Here the elements
//! are cut into a few contiguous blocks, one task each; a task scatters its
//! block's forces into its own buffer, which covers only the span of nodes
//! the block touches (meshes number their nodes and elements ring by ring or
//! row by row, so the spans barely overlap). The buffers are then summed
//! into the nodal forces in parallel over node ranges, each node adding the
//! buffers of the blocks that touch it in block order: the result is the
//! same whatever the scheduling, and equals the serial sum up to the order
//! of the additions (round-off).
//!
//! * triangle path (every model): each triangle's springs and pressure;
//! * spring path (Van Gelder and Lloyd with a constant modulus): each
//!   spring, then each triangle's pressure, in the same task.

use std::ops::Range;

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::SimError;
use super::mesh::Mesh;
use super::springs::Membrane;

/// One task: its elements and its buffer over the nodes they touch.
struct Block {
    tris: Range<usize>,
    edges: Range<usize>,
    /// First node of the span; the buffer holds `lo..lo + buf.len()`.
    lo: usize,
    buf: Vec<Vector3<f64>>,
}

/// Blocks and buffers for parallel force evaluation.
pub struct ParForces {
    blocks: Vec<Block>,
}

/// The span `[lo, hi)` of the nodes of some elements.
fn span<'a>(nodes: impl Iterator<Item = &'a u32>) -> Option<(usize, usize)> {
    nodes.fold(None, |s, &v| {
        let v = v as usize;
        Some(s.map_or((v, v + 1), |(lo, hi): (usize, usize)| {
            (lo.min(v), hi.max(v + 1))
        }))
    })
}

/// `n` cut into `k` nearly equal contiguous ranges.
fn cut(n: usize, k: usize) -> impl Iterator<Item = Range<usize>> {
    (0..k).map(move |i| i * n / k..(i + 1) * n / k)
}

impl ParForces {
    /// Indexes a mesh for a membrane built on it, in blocks for the current
    /// rayon pool (four per thread, for balance).
    pub fn new(mesh: &Mesh, membrane: &Membrane) -> ParForces {
        let springs = membrane.has_spring_path();
        let k = (4 * rayon::current_num_threads()).max(1);
        let blocks = cut(mesh.triangles.len(), k)
            .zip(cut(mesh.edges.len(), k))
            .map(|(tris, edges)| {
                let t = span(mesh.triangles[tris.clone()].iter().flatten());
                let e = if springs {
                    span(mesh.edges[edges.clone()].iter().flatten())
                } else {
                    None
                };
                let (lo, hi) = match (t, e) {
                    (Some(a), Some(b)) => (a.0.min(b.0), a.1.max(b.1)),
                    (Some(a), None) | (None, Some(a)) => a,
                    (None, None) => (0, 0),
                };
                Block {
                    tris,
                    edges,
                    lo,
                    buf: vec![Vector3::zeros(); hi - lo],
                }
            })
            .collect();
        ParForces { blocks }
    }

    /// Net nodal forces as [`Membrane::forces`], in parallel on the current
    /// rayon pool.
    pub fn forces(
        &mut self,
        m: &Membrane,
        x: &[Point3<f64>],
        f: &mut [Vector3<f64>],
    ) -> Result<(), SimError> {
        let springs = m.has_spring_path();
        self.blocks
            .par_iter_mut()
            .try_for_each(|b| -> Result<(), SimError> {
                b.buf.iter_mut().for_each(|v| *v = Vector3::zeros());
                if springs {
                    m.add_springs(b.edges.clone(), b.tris.clone(), x, &mut b.buf, b.lo);
                    Ok(())
                } else {
                    m.add_triangles(b.tris.clone(), x, &mut b.buf, b.lo)
                }
            })?;
        // Gather: node ranges in parallel, each adding the blocks over it.
        let blocks = &self.blocks;
        let chunk = f.len().div_ceil(4 * rayon::current_num_threads()).max(1024);
        f.par_chunks_mut(chunk).enumerate().for_each(|(c, out)| {
            let first = c * chunk;
            out.iter_mut().for_each(|v| *v = Vector3::zeros());
            for b in blocks {
                let (lo, hi) = (b.lo.max(first), (b.lo + b.buf.len()).min(first + out.len()));
                for i in lo..hi {
                    out[i - first] += b.buf[i - b.lo];
                }
            }
        });
        for (i, load) in &m.node_loads {
            f[*i] += load;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{Material, Model};
    use crate::sim::mesh::{self, DiscOptions};
    use crate::sim::springs::SpringModel;

    /// The parallel forces equal the serial ones (to round-off) for every
    /// model, with pressure, on a deformed disc, in a pool of two threads.
    #[test]
    fn parallel_equals_serial() {
        let m = mesh::disc(DiscOptions {
            radius_m: 1.0,
            rings: 12,
            sector: false,
        })
        .unwrap();
        let x: Vec<Point3<f64>> = m
            .nodes
            .iter()
            .enumerate()
            .map(|(i, p)| {
                Point3::new(
                    p.x * 1.03 + 0.01 * (i as f64).sin(),
                    p.y * 0.99,
                    0.3 * (1.0 - p.x * p.x - p.y * p.y),
                )
            })
            .collect();
        let mat = Material {
            model: Model::Linear { young_pa: 2.0e6 },
            poisson: 0.4,
            fit: None,
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        for model in SpringModel::ALL {
            let mut mem = Membrane::new(&m, model, &mat, 1e-3, 1000.0).unwrap();
            mem.pressure_pa = 3000.0;
            let mut a = vec![Vector3::zeros(); x.len()];
            mem.forces(&x, &mut a).unwrap();
            let mut pf = pool.install(|| ParForces::new(&m, &mem));
            let mut b = vec![Vector3::zeros(); x.len()];
            pool.install(|| pf.forces(&mem, &x, &mut b)).unwrap();
            let scale = a.iter().map(|v| v.norm()).fold(0.0, f64::max);
            for i in 0..x.len() {
                assert!(
                    (a[i] - b[i]).norm() <= 1e-12 * scale,
                    "{model:?} node {i}: {} vs {}",
                    a[i],
                    b[i]
                );
            }
        }
    }
}
