//! Spring models of a triangle membrane and the forces on its nodes.
//!
//! Per triangle `T` with rest sides `a0, b0, c0` (side `k` opposite vertex
//! `k`), rest area `|T0|`, current sides `a, b, c` and area `|T|`, thickness
//! `t`, Poisson ratio `nu` and modulus `E` (see *Modulus* below). Each side is
//! a spring along the current edge; its tension is summed over the one or two
//! triangles that hold it.
//!
//! * **TP MSS, division-free** (`tp`, the default; Tudruj et al. (2023) eqs 9-13 times
//!   the extension): with `Q = E t / (8 (1 - nu^2) |T0|)` (eq 12),
//!   `eps_t_x = x / x0 - 1`, `eps_n_x = h_x / h_x0 - 1 = |T| x0 / (|T0| x) - 1`
//!   and `q_x = eps_n_x + nu eps_t_x` (eq 9), the tension of side `b` is
//!   `F_b = Q (a0^2 q_a - b0^2 q_b + c0^2 q_c) b0`. This equals eq 11's
//!   `k_b (b - b0)` wherever `eps_t_b != 0` and stays continuous where it is 0.
//! * **TP MSS as printed** (`tp-paper`): `k_b` from eq 11 (division by
//!   `eps_t_b`), replaced by eq 16 `k_b = Q0 (a0^2 - b0^2 + c0^2)`,
//!   `Q0 = E t / (8 (1 - nu) |T0|)` (eq 17) when `|eps_t_b| <= 1e-12`, and
//!   `F_b = k_b (b - b0)`. At exactly zero side strain the tension is zero
//!   whatever the other sides do: the discontinuity the force form removes.
//! * **Van Gelder** (`van-gelder`, eq 1): `k_c = E t / (1 + nu) |T0| / c0^2 +
//!   E t nu / (1 - nu^2) (a0^2 + b0^2 - c0^2) / (8 |T0|)`, `F_c = k_c (c - c0)`.
//! * **Lloyd** (`lloyd`, eq 4): `k_c = E t sqrt(3)/4 |T0| / |T0c|` with
//!   `|T0c| = sqrt(3)/4 c0^2`, i.e. `k_c = E t |T0| / c0^2`, the same as Van
//!   Gelder's eq 2 at nu = 0.
//!
//! Van Gelder and Lloyd springs are linear with a stiffness set by the rest
//! geometry; with a constant `E` they have the energy `1/2 sum k (l - l0)^2`.
//!
//! ## Modulus
//! `E` is evaluated per triangle at its equibiaxial-equivalent stretch
//! `lambda = sqrt(|T| / |T0|)`, the in-plane area stretch's square root. The
//! quartic law is fitted on the bubble's pole, which is stretched
//! equibiaxially, so a triangle is given the modulus of the equibiaxial state
//! with its area; the measure is invariant under rotation, cheap (the area is
//! needed anyway) and exactly the bubble's stretch where the membrane is
//! equibiaxial.
//!
//! * `linear`: `E = young_pa`, constant.
//! * `quartic`: `E = sum c_k eps^k` with `eps` the law's `strain_measure` of
//!   `lambda` (`lambda - 1` or `ln lambda`), **clamped to `strain_range`**:
//!   outside the fitted range the law is held at its end value (a quartic
//!   extrapolated swings fast, and held values keep `E` continuous and
//!   bounded). `E <= 0` met inside the range stops the solve with the strain.
//! * hyperelastic models: the equibiaxial secant modulus
//!   `E = (1 - nu) P(lambda) / (lambda - 1)` with `P = dW/dlambda` the nominal
//!   equibiaxial stress (Tudruj et al. 2023, section 7, "for the 2D case"); with it the TP
//!   springs carry exactly the material's equibiaxial tension per current
//!   length, `P t / lambda`. At `lambda -> 1` the limit `(1 - nu) dP/dlambda`.
//!
//! ## Loads
//! Follower pressure on the current triangles: each vertex gets one third of
//! `p |T| n`. Nodal loads are constant vectors. Lumped masses: one third of
//! `rho t |T0|` per vertex (the membrane analogue of the quarter-tetrahedron
//! lumping of Sudhamani & Merriliance 2019).

use nalgebra::{Point3, Vector3};

use super::SimError;
use super::cst::{CstLaw, CstRest, LawFailure};
use super::mesh::{Constraint, Mesh};
use crate::material::Material;

mod law;
pub use law::*;

/// The membrane model: a spring-stiffness model, or the constant-strain
/// triangle membrane that carries the material's whole law
/// ([`super::cst`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum SpringModel {
    /// TP MSS in the division-free force form (default).
    Tp,
    /// TP MSS eq 11 as printed, eq 16 at zero side strain.
    TpPaper,
    /// Van Gelder eq 1.
    VanGelder,
    /// Lloyd et al. eq 4.
    Lloyd,
    /// Constant-strain triangles with the material's strain energy.
    Membrane,
}

impl SpringModel {
    /// All models.
    pub const ALL: [SpringModel; 5] = [
        SpringModel::Tp,
        SpringModel::TpPaper,
        SpringModel::VanGelder,
        SpringModel::Lloyd,
        SpringModel::Membrane,
    ];

    /// The mass-spring models (all but the membrane).
    pub const SPRINGS: [SpringModel; 4] = [
        SpringModel::Tp,
        SpringModel::TpPaper,
        SpringModel::VanGelder,
        SpringModel::Lloyd,
    ];

    /// Name used on the command line and in output files.
    pub fn name(self) -> &'static str {
        match self {
            SpringModel::Tp => "tp",
            SpringModel::TpPaper => "tp-paper",
            SpringModel::VanGelder => "van-gelder",
            SpringModel::Lloyd => "lloyd",
            SpringModel::Membrane => "membrane",
        }
    }

    /// Parses a name.
    pub fn parse(s: &str) -> Option<SpringModel> {
        Self::ALL.into_iter().find(|m| m.name() == s.trim())
    }
}

/// A model that gives simulated heights: a spring model, or the exact
/// axisymmetric solution of the same material. Keys the runs of a simulation
/// and the rows of the error table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HeightModel {
    /// A mass-spring model on a triangle mesh.
    Spring(SpringModel),
    /// The exact axisymmetric membrane ([`crate::axisym`]); discs only.
    Axisym,
}

impl HeightModel {
    /// Name used on the command line, in column names and in reports.
    pub fn name(self) -> &'static str {
        match self {
            HeightModel::Spring(m) => m.name(),
            HeightModel::Axisym => "axisym",
        }
    }

    /// The spring model, if it is one.
    pub fn spring(self) -> Option<SpringModel> {
        match self {
            HeightModel::Spring(m) => Some(m),
            HeightModel::Axisym => None,
        }
    }
}

impl std::fmt::Display for HeightModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A model name that is none of bulge's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{0}` is not one of tp, tp-paper, van-gelder, lloyd, membrane, axisym")]
pub struct UnknownHeightModel(pub String);

impl std::str::FromStr for HeightModel {
    type Err = UnknownHeightModel;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim() {
            "axisym" => Ok(HeightModel::Axisym),
            other => SpringModel::parse(other)
                .map(HeightModel::Spring)
                .ok_or_else(|| UnknownHeightModel(s.trim().to_string())),
        }
    }
}

impl From<SpringModel> for HeightModel {
    fn from(m: SpringModel) -> Self {
        HeightModel::Spring(m)
    }
}

/// Rest data of one triangle.
#[derive(Debug, Clone, Copy)]
struct Tri {
    v: [u32; 3],
    l0: [f64; 3],
    l0sq: [f64; 3],
    /// `1 / l0` per side (the force loop multiplies instead of dividing).
    inv_l0: [f64; 3],
    area0: f64,
    /// `1 / area0`.
    inv_area0: f64,
    /// TP: `t / (8 (1 - nu^2) |T0|)` in [0], `t / (8 (1 - nu) |T0|)` in [1];
    /// Van Gelder / Lloyd: `k_k / E` per side.
    c: [f64; 3],
}

/// Where element forces go: a node's force is added to.
pub trait NodeSink {
    /// Adds `v` to node `i`'s force.
    fn add(&mut self, i: usize, v: Vector3<f64>);
}

/// The whole nodal force array.
impl NodeSink for &mut [Vector3<f64>] {
    #[inline(always)]
    fn add(&mut self, i: usize, v: Vector3<f64>) {
        self[i] += v;
    }
}

/// A law failure of the membrane model as the solver's error.
fn law_error(e: LawFailure, triangle: usize) -> SimError {
    match e {
        LawFailure::Modulus { strain, young_pa } => SimError::NonPositiveModulus {
            strain,
            young_pa,
            triangle,
        },
        LawFailure::Domain { stretches } => SimError::OutsideLaw {
            triangle,
            stretches,
        },
    }
}

/// Side `k` of a triangle joins vertices `(k+1)%3` and `(k+2)%3`.
const SIDE: [(usize, usize); 3] = [(1, 2), (2, 0), (0, 1)];

/// Side strain below which `tp-paper` switches to eq 16.
pub const TP_PAPER_SWITCH: f64 = 1e-12;

/// The membrane: rest data, spring model, modulus law and loads. Evaluates
/// nodal forces for any positions; owns no positions itself.
#[derive(Debug, Clone)]
pub struct Membrane {
    /// Spring model.
    pub model: SpringModel,
    /// Modulus law.
    pub law: ModulusLaw,
    /// Thickness, m.
    pub thickness_m: f64,
    /// Poisson ratio.
    pub poisson: f64,
    /// Follower pressure on the triangles, Pa.
    pub pressure_pa: f64,
    /// Constant nodal loads, N.
    pub node_loads: Vec<(usize, Vector3<f64>)>,
    /// Per-node constraints (copied from the mesh).
    pub constraints: Vec<Constraint>,
    /// Lumped masses, kg.
    pub masses: Vec<f64>,
    tris: Vec<Tri>,
    edges: Vec<[u32; 2]>,
    edge_l0: Vec<f64>,
    /// Constant spring stiffness per edge (Van Gelder and Lloyd with a constant E).
    edge_k: Option<Vec<f64>>,
    /// The membrane model: its law and the rest data of every triangle.
    cst: Option<(CstLaw, Vec<CstRest>)>,
}

impl Membrane {
    /// Prepares the rest data of a mesh for a model and material.
    pub fn new(
        mesh: &Mesh,
        model: SpringModel,
        material: &Material,
        thickness_m: f64,
        density_kg_m3: f64,
    ) -> Result<Membrane, SimError> {
        let law = ModulusLaw::from_material(material)?;
        if !(thickness_m.is_finite() && thickness_m > 0.0) {
            return Err(SimError::BadParameter(format!(
                "thickness_m = {thickness_m} must be a positive length in metres"
            )));
        }
        if !(density_kg_m3.is_finite() && density_kg_m3 > 0.0) {
            return Err(SimError::BadParameter(format!(
                "density_kg_m3 = {density_kg_m3} must be a positive density (rubber: about 1100)"
            )));
        }
        let nu = material.poisson;
        let t = thickness_m;
        let mut masses = vec![0.0; mesh.nodes.len()];
        let mut tris = Vec::with_capacity(mesh.triangles.len());
        for (ti, tri) in mesh.triangles.iter().enumerate() {
            let p = tri.map(|i| mesh.nodes[i as usize]);
            let area0 = (p[1] - p[0]).cross(&(p[2] - p[0])).norm() / 2.0;
            if area0.is_nan() || area0 <= 0.0 {
                return Err(SimError::DegenerateTriangle {
                    triangle: ti,
                    nodes: *tri,
                    area_m2: area0,
                });
            }
            let mut l0 = [0.0; 3];
            for (k, (i, j)) in SIDE.iter().enumerate() {
                l0[k] = (p[*j] - p[*i]).norm();
            }
            let l0sq = l0.map(|l| l * l);
            let c = match model {
                SpringModel::Tp | SpringModel::TpPaper => [
                    t / (8.0 * (1.0 - nu * nu) * area0),
                    t / (8.0 * (1.0 - nu) * area0),
                    0.0,
                ],
                SpringModel::VanGelder => std::array::from_fn(|k| {
                    let (i, j) = SIDE[k];
                    t / (1.0 + nu) * area0 / l0sq[k]
                        + t * nu / (1.0 - nu * nu) * (l0sq[i] + l0sq[j] - l0sq[k]) / (8.0 * area0)
                }),
                SpringModel::Lloyd => std::array::from_fn(|k| t * area0 / l0sq[k]),
                SpringModel::Membrane => [0.0; 3],
            };
            for &i in tri {
                masses[i as usize] += density_kg_m3 * t * area0 / 3.0;
            }
            tris.push(Tri {
                v: *tri,
                l0,
                l0sq,
                inv_l0: l0.map(|v| 1.0 / v),
                area0,
                inv_area0: 1.0 / area0,
                c,
            });
        }
        let edge_l0: Vec<f64> = mesh
            .edges
            .iter()
            .map(|e| (mesh.nodes[e[1] as usize] - mesh.nodes[e[0] as usize]).norm())
            .collect();
        let edge_k = match (&law, model) {
            (ModulusLaw::Constant(e), SpringModel::VanGelder | SpringModel::Lloyd) => {
                let mut k = vec![0.0; mesh.edges.len()];
                for (tri, te) in tris.iter().zip(&mesh.triangle_edges) {
                    for s in 0..3 {
                        k[te[s] as usize] += e * tri.c[s];
                    }
                }
                Some(k)
            }
            _ => None,
        };
        let cst = (model == SpringModel::Membrane).then(|| {
            let rest = mesh
                .triangles
                .iter()
                .map(|tri| CstRest::new(&tri.map(|i| mesh.nodes[i as usize]), t))
                .collect();
            (CstLaw::from_material(material), rest)
        });
        Ok(Membrane {
            model,
            law,
            thickness_m,
            poisson: nu,
            pressure_pa: 0.0,
            node_loads: Vec::new(),
            constraints: mesh.constraints.clone(),
            masses,
            tris,
            edges: mesh.edges.clone(),
            edge_l0,
            edge_k,
            cst,
        })
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.constraints.len()
    }

    /// Number of triangles.
    pub fn triangles(&self) -> usize {
        self.tris.len()
    }

    /// Number of springs (unique edges).
    pub fn springs(&self) -> usize {
        self.edges.len()
    }

    /// Shortest rest edge, m.
    pub fn min_rest_edge(&self) -> f64 {
        self.edge_l0.iter().cloned().fold(f64::INFINITY, f64::min)
    }

    /// Node indices of triangle `t`.
    pub fn triangle_nodes(&self, t: usize) -> [u32; 3] {
        self.tris[t].v
    }

    /// Node indices of spring `e`.
    pub fn spring_nodes(&self, e: usize) -> [u32; 2] {
        self.edges[e]
    }

    /// Rest area of triangle `t`, m^2.
    pub fn rest_area(&self, t: usize) -> f64 {
        self.tris[t].area0
    }

    /// Net nodal forces (springs + pressure + nodal loads), N, at positions
    /// `x`, written into `f` (overwritten; not projected on the constraints).
    /// Allocation-free.
    pub fn forces(&self, x: &[Point3<f64>], f: &mut [Vector3<f64>]) -> Result<(), SimError> {
        assert_eq!(x.len(), f.len());
        for v in f.iter_mut() {
            *v = Vector3::zeros();
        }
        if self.edge_k.is_some() {
            self.add_springs(0..self.edges.len(), 0..self.tris.len(), x, &mut &mut *f);
        } else {
            self.add_triangles(0..self.tris.len(), x, &mut &mut *f)?;
        }
        for (i, load) in &self.node_loads {
            f[*i] += load;
        }
        Ok(())
    }

    /// True when the forces take the spring path (Van Gelder and Lloyd with
    /// a constant modulus: one stiffness per edge) rather than the triangle
    /// path.
    pub fn has_spring_path(&self) -> bool {
        self.edge_k.is_some()
    }

    /// Adds the forces of triangles `tris` (their springs and pressure) to
    /// `out` (the serial loop, and the blocks of `sim::par`).
    pub fn add_triangles<S: NodeSink>(
        &self,
        tris: std::ops::Range<usize>,
        x: &[Point3<f64>],
        out: &mut S,
    ) -> Result<(), SimError> {
        for t in tris {
            let f = self.triangle_forces(t, x)?;
            for (v, fk) in self.tris[t].v.iter().zip(f) {
                out.add(*v as usize, fk);
            }
        }
        Ok(())
    }

    /// The spring path: adds the forces of the springs `edges` and the
    /// pressure of the triangles `tris` to `out`. Panics without a spring
    /// path ([`Membrane::has_spring_path`]).
    pub fn add_springs<S: NodeSink>(
        &self,
        edges: std::ops::Range<usize>,
        tris: std::ops::Range<usize>,
        x: &[Point3<f64>],
        out: &mut S,
    ) {
        let k = self.edge_k.as_ref().expect("the spring path");
        for e in edges {
            let (i, j) = (self.edges[e][0] as usize, self.edges[e][1] as usize);
            let d = x[j] - x[i];
            let l = d.norm();
            let fv = d * (k[e] * (l - self.edge_l0[e]) / l);
            out.add(i, fv);
            out.add(j, -fv);
        }
        let p6 = self.pressure_pa / 6.0;
        if p6 != 0.0 {
            for t in tris {
                let [a, b, c] = self.tris[t].v.map(|i| i as usize);
                let n2 = (x[b] - x[a]).cross(&(x[c] - x[a])) * p6;
                out.add(a, n2);
                out.add(b, n2);
                out.add(c, n2);
            }
        }
    }

    /// Removes the constrained components of nodal vectors.
    pub fn project(&self, f: &mut [Vector3<f64>]) {
        for (v, c) in f.iter_mut().zip(&self.constraints) {
            *v = c.project(*v);
        }
    }

    /// Net force of one triangle (its three springs' shares and its pressure)
    /// on its three vertices; `Err((strain, E))` when `E <= 0` or not finite.
    #[inline(always)]
    fn local(&self, tri: &Tri, p: &[Point3<f64>; 3]) -> Result<[Vector3<f64>; 3], (f64, f64)> {
        let d: [Vector3<f64>; 3] = std::array::from_fn(|k| p[SIDE[k].1] - p[SIDE[k].0]);
        let l: [f64; 3] = std::array::from_fn(|k| d[k].norm());
        let inv_l: [f64; 3] = l.map(|v| 1.0 / v);
        let n2 = d[2].cross(&(-d[1])); // (p1 - p0) x (p2 - p0)
        let area = n2.norm() / 2.0;
        let area_ratio = area * tri.inv_area0;
        let (strain, e) = match self.law {
            // Validated positive when the membrane was built.
            ModulusLaw::Constant(e) => (0.0, e),
            _ => self.law.young(area_ratio.sqrt()),
        };
        if !(e > 0.0 && e.is_finite()) {
            return Err((strain, e));
        }
        let tension: [f64; 3] = match self.model {
            SpringModel::Tp | SpringModel::TpPaper => {
                let nu = self.poisson;
                let q: [f64; 3] = std::array::from_fn(|k| {
                    let et = l[k] * tri.inv_l0[k] - 1.0;
                    let en = area_ratio * tri.l0[k] * inv_l[k] - 1.0;
                    en + nu * et
                });
                let s = tri.l0sq[0] * q[0] + tri.l0sq[1] * q[1] + tri.l0sq[2] * q[2];
                let qq = e * tri.c[0];
                if self.model == SpringModel::Tp {
                    std::array::from_fn(|k| qq * (s - 2.0 * tri.l0sq[k] * q[k]) * tri.l0[k])
                } else {
                    let q0 = e * tri.c[1];
                    let sum0 = tri.l0sq[0] + tri.l0sq[1] + tri.l0sq[2];
                    std::array::from_fn(|k| {
                        let et = (l[k] - tri.l0[k]) * tri.inv_l0[k];
                        let kk = if et.abs() > TP_PAPER_SWITCH {
                            qq * (s - 2.0 * tri.l0sq[k] * q[k]) / et
                        } else {
                            q0 * (sum0 - 2.0 * tri.l0sq[k])
                        };
                        kk * (l[k] - tri.l0[k])
                    })
                }
            }
            SpringModel::VanGelder | SpringModel::Lloyd => {
                std::array::from_fn(|k| e * tri.c[k] * (l[k] - tri.l0[k]))
            }
            SpringModel::Membrane => unreachable!("the membrane model has no springs"),
        };
        let pn = n2 * (self.pressure_pa / 6.0);
        let mut out = [pn; 3];
        for k in 0..3 {
            let (i, j) = SIDE[k];
            let fv = d[k] * (tension[k] * inv_l[k]);
            out[i] += fv;
            out[j] -= fv;
        }
        Ok(out)
    }

    /// Stiffness of triangle `t` (its springs and its pressure), `-d f / d x`
    /// as a 9x9 matrix over its vertices' coordinates: for the spring models
    /// by central differences of the local forces (step 1e-6 of the
    /// shortest rest side; truncation and round-off both below 1e-9 of the
    /// stiffness), for the membrane model exact ([`CstRest::stiffness`]).
    pub fn triangle_stiffness(
        &self,
        t: usize,
        x: &[Point3<f64>],
    ) -> Result<[[f64; 9]; 9], SimError> {
        let tri = &self.tris[t];
        if let Some((law, rest)) = &self.cst {
            let p = tri.v.map(|i| x[i as usize]);
            return rest[t]
                .stiffness(law, self.pressure_pa, &p)
                .map_err(|e| law_error(e, t));
        }
        let h = 1e-6 * tri.l0[0].min(tri.l0[1]).min(tri.l0[2]);
        let p0 = tri.v.map(|i| x[i as usize]);
        let err = |(strain, young_pa)| SimError::NonPositiveModulus {
            strain,
            young_pa,
            triangle: t,
        };
        let mut k = [[0.0; 9]; 9];
        for col in 0..9 {
            let mut pp = p0;
            pp[col / 3][col % 3] += h;
            let fp = self.local(tri, &pp).map_err(err)?;
            let mut pm = p0;
            pm[col / 3][col % 3] -= h;
            let fm = self.local(tri, &pm).map_err(err)?;
            for row in 0..9 {
                k[row][col] = -(fp[row / 3][row % 3] - fm[row / 3][row % 3]) / (2.0 * h);
            }
        }
        Ok(k)
    }

    /// An upper bound of each node's stiffness row sum (Gershgorin), N/m,
    /// for the fictitious masses of dynamic relaxation and the stable step of
    /// explicit integrators.
    pub fn stiffness_bounds(&self, x: &[Point3<f64>], s: &mut [f64]) -> Result<(), SimError> {
        for v in s.iter_mut() {
            *v = 0.0;
        }
        for t in 0..self.tris.len() {
            let k = self.triangle_stiffness(t, x)?;
            let v = self.tris[t].v;
            for a in 0..3 {
                let mut row_max = 0.0_f64;
                for r in 0..3 {
                    let sum: f64 = k[3 * a + r].iter().map(|x| x.abs()).sum();
                    row_max = row_max.max(sum);
                }
                s[v[a] as usize] += row_max;
            }
        }
        Ok(())
    }

    /// Area stretch `sqrt(|T| / |T0|)` of every triangle (for output).
    pub fn triangle_stretch(&self, x: &[Point3<f64>]) -> Vec<f64> {
        self.tris
            .iter()
            .map(|tri| {
                let p = tri.v.map(|i| x[i as usize]);
                ((p[1] - p[0]).cross(&(p[2] - p[0])).norm() / 2.0 / tri.area0).sqrt()
            })
            .collect()
    }

    /// Elastic energy, J: of the springs for Van Gelder and Lloyd with a
    /// constant E (`1/2 sum k (l - l0)^2`), of the triangles for the
    /// membrane model with an energy (every law but the quartic); `None`
    /// for the others, which have none.
    pub fn spring_energy(&self, x: &[Point3<f64>]) -> Option<f64> {
        if let Some((law, rest)) = &self.cst {
            return rest
                .iter()
                .zip(&self.tris)
                .map(|(r, tri)| r.energy(law, &tri.v.map(|i| x[i as usize])))
                .sum();
        }
        let k = self.edge_k.as_ref()?;
        Some(
            self.edges
                .iter()
                .zip(k)
                .zip(&self.edge_l0)
                .map(|((e, k), l0)| {
                    let l = (x[e[1] as usize] - x[e[0] as usize]).norm();
                    0.5 * k * (l - l0) * (l - l0)
                })
                .sum(),
        )
    }

    /// Net force of triangle `t` (its springs' shares and its pressure) on
    /// its three vertices at positions `x` (added for the parallel force
    /// loop of `sim::par`).
    #[inline]
    pub fn triangle_forces(
        &self,
        t: usize,
        x: &[Point3<f64>],
    ) -> Result<[Vector3<f64>; 3], SimError> {
        let tri = &self.tris[t];
        let p = tri.v.map(|i| x[i as usize]);
        if let Some((law, rest)) = &self.cst {
            return rest[t]
                .forces(law, self.pressure_pa, &p)
                .map_err(|e| law_error(e, t));
        }
        self.local(tri, &p)
            .map_err(|(strain, young_pa)| SimError::NonPositiveModulus {
                strain,
                young_pa,
                triangle: t,
            })
    }

    /// The per-triangle force path even where the edge fast path exists (for
    /// tests comparing the two).
    pub fn forces_by_triangle(
        &self,
        x: &[Point3<f64>],
        f: &mut [Vector3<f64>],
    ) -> Result<(), SimError> {
        for v in f.iter_mut() {
            *v = Vector3::zeros();
        }
        self.add_triangles(0..self.tris.len(), x, &mut &mut *f)?;
        for (i, load) in &self.node_loads {
            f[*i] += load;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
