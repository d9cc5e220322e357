//! Parallel nodal forces (rayon), for meshes of 1e4 nodes and more.
//!
//! [`Membrane::forces`] scatters each triangle's (or spring's) force into its
//! nodes, which a parallel loop cannot do without races. Here the elements
//! are cut into a few contiguous blocks, one task each, and the nodes into
//! as many contiguous ranges, one owned by each block: meshes number their
//! nodes and elements ring by ring or row by row, so a block's elements
//! touch mostly the nodes it owns. A task zeroes its own range of the nodal
//! forces and adds its elements' forces there directly; the few forces on
//! nodes it does not own go to its small halo buffers, added afterwards in
//! block order. The result is the same whatever the scheduling, and equals
//! the serial sum up to the order of the additions (round-off).
//!
//! * triangle path (every model): each triangle's springs and pressure;
//! * spring path (Van Gelder and Lloyd with a constant modulus): each
//!   spring, then each triangle's pressure, in the same task.

use std::ops::Range;

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::SimError;
use super::mesh::Mesh;
use super::springs::{Membrane, NodeSink};

/// One task: its elements, the nodes it owns and its halo buffers.
struct Block {
    tris: Range<usize>,
    edges: Range<usize>,
    /// First node its elements touch.
    lo: usize,
    /// Nodes it owns.
    own: Range<usize>,
    /// Forces on nodes `lo..own.start`.
    low: Vec<Vector3<f64>>,
    /// Forces on nodes `own.end..own.end + high.len()`.
    high: Vec<Vector3<f64>>,
}

/// A block's view of the nodal forces: its own range, then its halos.
struct Owned<'a> {
    own: &'a mut [Vector3<f64>],
    start: usize,
    lo: usize,
    low: &'a mut [Vector3<f64>],
    high: &'a mut [Vector3<f64>],
}

impl NodeSink for Owned<'_> {
    #[inline(always)]
    fn add(&mut self, i: usize, v: Vector3<f64>) {
        let k = i.wrapping_sub(self.start);
        if k < self.own.len() {
            self.own[k] += v;
        } else if i < self.start {
            self.low[i - self.lo] += v;
        } else {
            self.high[k - self.own.len()] += v;
        }
    }
}

/// Blocks and halo buffers for parallel force evaluation.
pub struct ParForces {
    blocks: Vec<Block>,
    nodes: usize,
}

/// The span `[lo, hi)` of the nodes of some elements.
fn span(nodes: impl Iterator<Item = u32>) -> Option<(usize, usize)> {
    nodes.fold(None, |s, v| {
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
    /// rayon pool (one per thread: fewer blocks, fewer shared nodes).
    pub fn new(mesh: &Mesh, membrane: &Membrane) -> ParForces {
        debug_assert_eq!(mesh.triangles.len(), membrane.triangles());
        ParForces::for_membrane(membrane)
    }

    /// Indexes a membrane's triangles and springs, in blocks for the current
    /// rayon pool (one per thread: fewer blocks, fewer shared nodes).
    pub fn for_membrane(membrane: &Membrane) -> ParForces {
        let n = membrane.nodes();
        let springs = membrane.has_spring_path();
        let k = rayon::current_num_threads().max(1);
        let spans: Vec<(Range<usize>, Range<usize>, usize, usize)> = cut(membrane.triangles(), k)
            .zip(cut(membrane.springs(), k))
            .map(|(tris, edges)| {
                let t = span(tris.clone().flat_map(|t| membrane.triangle_nodes(t)));
                let e = if springs {
                    span(edges.clone().flat_map(|e| membrane.spring_nodes(e)))
                } else {
                    None
                };
                let (lo, hi) = match (t, e) {
                    (Some(a), Some(b)) => (a.0.min(b.0), a.1.max(b.1)),
                    (Some(a), None) | (None, Some(a)) => a,
                    (None, None) => (0, 0),
                };
                (tris, edges, lo, hi)
            })
            .collect();
        // Cut points: block b owns [cut_b, cut_{b+1}), cut_b = max(lo_b,
        // cut_{b-1}), the first from node 0 and the last to node n.
        let mut cuts = vec![0usize; spans.len() + 1];
        for b in 1..spans.len() {
            cuts[b] = spans[b].2.max(cuts[b - 1]).min(n);
        }
        cuts[spans.len()] = n;
        let blocks = spans
            .into_iter()
            .enumerate()
            .map(|(b, (tris, edges, lo, hi))| {
                let own = cuts[b]..cuts[b + 1];
                let lo = lo.min(own.start);
                Block {
                    tris,
                    edges,
                    lo,
                    low: vec![Vector3::zeros(); own.start - lo],
                    high: vec![Vector3::zeros(); hi.saturating_sub(own.end)],
                    own,
                }
            })
            .collect();
        ParForces { blocks, nodes: n }
    }

    /// Net nodal forces as [`Membrane::forces`], in parallel on the current
    /// rayon pool.
    pub fn forces(
        &mut self,
        m: &Membrane,
        x: &[Point3<f64>],
        f: &mut [Vector3<f64>],
    ) -> Result<(), SimError> {
        assert_eq!(
            f.len(),
            self.nodes,
            "one force per node of the indexed mesh"
        );
        let springs = m.has_spring_path();
        let mut tasks = Vec::with_capacity(self.blocks.len());
        let mut rest = &mut *f;
        for b in &mut self.blocks {
            let (own, tail) = rest.split_at_mut(b.own.len());
            rest = tail;
            tasks.push((b, own));
        }
        tasks
            .into_par_iter()
            .try_for_each(|(b, own)| -> Result<(), SimError> {
                own.iter_mut().for_each(|v| *v = Vector3::zeros());
                b.low.iter_mut().for_each(|v| *v = Vector3::zeros());
                b.high.iter_mut().for_each(|v| *v = Vector3::zeros());
                let mut sink = Owned {
                    own,
                    start: b.own.start,
                    lo: b.lo,
                    low: &mut b.low,
                    high: &mut b.high,
                };
                if springs {
                    m.add_springs(b.edges.clone(), b.tris.clone(), x, &mut sink);
                    Ok(())
                } else {
                    m.add_triangles(b.tris.clone(), x, &mut sink)
                }
            })?;
        // The halos, in block order.
        for b in &self.blocks {
            for (k, v) in b.low.iter().enumerate() {
                f[b.lo + k] += v;
            }
            for (k, v) in b.high.iter().enumerate() {
                f[b.own.end + k] += v;
            }
        }
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
