//! Parallel nodal forces (rayon), for meshes of 1e4 nodes and more.
//!
//! [`Membrane::forces`] scatters each triangle's (or spring's) force into its
//! nodes, which a parallel loop cannot do without races. Here every triangle
//! (or spring) writes its forces into its own slots of a buffer, in parallel,
//! and every node then gathers its slots, in parallel, through a node ->
//! slots index built once ([`ParForces::new`]). The result equals the serial
//! sum up to the order of the additions (round-off).
//!
//! * triangle path (every model): per-triangle forces incl. the pressure,
//!   9 doubles per triangle;
//! * spring path (Van Gelder and Lloyd with a constant modulus): per-spring
//!   force vector, then the pressure per triangle.

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::SimError;
use super::dynamics::reference_edge_stiffness;
use super::mesh::Mesh;
use super::springs::{Membrane, SpringModel};

/// Buffers and gather indices for parallel force evaluation.
pub struct ParForces {
    /// node -> (triangle * 3 + corner) slots.
    tri_ptr: Vec<usize>,
    tri_slots: Vec<u32>,
    /// node -> signed edge slots (edge * 2 + 0 for +, + 1 for -).
    edge_ptr: Vec<usize>,
    edge_slots: Vec<u32>,
    tri_buf: Vec<[Vector3<f64>; 3]>,
    edge_buf: Vec<Vector3<f64>>,
    edges: Vec<[u32; 2]>,
    edge_l0: Vec<f64>,
    /// Spring stiffness for the spring path (`None`: triangle path).
    edge_k: Option<Vec<f64>>,
}

fn csr(n: usize, pairs: impl Iterator<Item = (usize, u32)> + Clone) -> (Vec<usize>, Vec<u32>) {
    let mut count = vec![0usize; n + 1];
    for (i, _) in pairs.clone() {
        count[i + 1] += 1;
    }
    for i in 0..n {
        count[i + 1] += count[i];
    }
    let mut fill = count.clone();
    let mut slots = vec![0u32; count[n]];
    for (i, s) in pairs {
        slots[fill[i]] = s;
        fill[i] += 1;
    }
    (count, slots)
}

impl ParForces {
    /// Indexes a mesh for a membrane built on it.
    pub fn new(mesh: &Mesh, membrane: &Membrane) -> ParForces {
        let n = mesh.nodes.len();
        let (tri_ptr, tri_slots) = csr(
            n,
            mesh.triangles
                .iter()
                .enumerate()
                .flat_map(|(t, v)| (0..3).map(move |k| (v[k] as usize, (3 * t + k) as u32))),
        );
        let (edge_ptr, edge_slots) = csr(
            n,
            mesh.edges.iter().enumerate().flat_map(|(e, v)| {
                [
                    (v[0] as usize, (2 * e) as u32),
                    (v[1] as usize, (2 * e + 1) as u32),
                ]
            }),
        );
        let edge_k = match (membrane.model, membrane.law.is_constant()) {
            (SpringModel::VanGelder | SpringModel::Lloyd, true) => Some(reference_edge_stiffness(
                mesh,
                membrane.model,
                membrane.law.young(1.0).1,
                membrane.poisson,
                membrane.thickness_m,
            )),
            _ => None,
        };
        ParForces {
            tri_ptr,
            tri_slots,
            edge_ptr,
            edge_slots,
            tri_buf: vec![[Vector3::zeros(); 3]; mesh.triangles.len()],
            edge_buf: vec![Vector3::zeros(); mesh.edges.len()],
            edges: mesh.edges.clone(),
            edge_l0: mesh
                .edges
                .iter()
                .map(|e| (mesh.nodes[e[1] as usize] - mesh.nodes[e[0] as usize]).norm())
                .collect(),
            edge_k,
        }
    }

    /// Net nodal forces as [`Membrane::forces`], in parallel on the current
    /// rayon pool.
    pub fn forces(
        &mut self,
        m: &Membrane,
        x: &[Point3<f64>],
        f: &mut [Vector3<f64>],
    ) -> Result<(), SimError> {
        let p6 = m.pressure_pa / 6.0;
        if let Some(k) = &self.edge_k {
            let (edges, l0) = (&self.edges, &self.edge_l0);
            self.edge_buf
                .par_iter_mut()
                .enumerate()
                .for_each(|(e, out)| {
                    let (i, j) = (edges[e][0] as usize, edges[e][1] as usize);
                    let d = x[j] - x[i];
                    let l = d.norm();
                    *out = d * (k[e] * (l - l0[e]) / l);
                });
            if p6 != 0.0 {
                self.tri_buf
                    .par_iter_mut()
                    .enumerate()
                    .for_each(|(t, out)| {
                        let [a, b, c] = m.triangle_nodes(t).map(|i| i as usize);
                        let n2 = (x[b] - x[a]).cross(&(x[c] - x[a])) * p6;
                        *out = [n2; 3];
                    });
            }
            let (ep, es, tp, ts, eb, tb) = (
                &self.edge_ptr,
                &self.edge_slots,
                &self.tri_ptr,
                &self.tri_slots,
                &self.edge_buf,
                &self.tri_buf,
            );
            f.par_iter_mut().enumerate().for_each(|(i, fi)| {
                let mut s = Vector3::zeros();
                for &slot in &es[ep[i]..ep[i + 1]] {
                    let v = eb[(slot / 2) as usize];
                    if slot % 2 == 0 { s += v } else { s -= v }
                }
                if p6 != 0.0 {
                    for &slot in &ts[tp[i]..tp[i + 1]] {
                        s += tb[(slot / 3) as usize][(slot % 3) as usize];
                    }
                }
                *fi = s;
            });
        } else {
            self.tri_buf.par_iter_mut().enumerate().try_for_each(
                |(t, out)| -> Result<(), SimError> {
                    *out = m.triangle_forces(t, x)?;
                    Ok(())
                },
            )?;
            let (tp, ts, tb) = (&self.tri_ptr, &self.tri_slots, &self.tri_buf);
            f.par_iter_mut().enumerate().for_each(|(i, fi)| {
                let mut s = Vector3::zeros();
                for &slot in &ts[tp[i]..tp[i + 1]] {
                    s += tb[(slot / 3) as usize][(slot % 3) as usize];
                }
                *fi = s;
            });
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
            let mut pf = ParForces::new(&m, &mem);
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
