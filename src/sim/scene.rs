//! Scene files: what to simulate, and the quantities reported.
//!
//! ```toml
//! kind = "disc"                 # disc | ellipse | rectangle | sphere-segment | sheet
//! radius_m = 0.0375             # disc: free radius a; sphere-segment: R0
//! # ellipse: semi_axes_m = [0.05, 0.025]; rectangle (and sheet): length_m, width_m
//! thickness_m = 0.00035         # initial thickness t
//! pressure_pa = [5000, 7300, 8940]
//! density_kg_m3 = 1100          # optional (default 1100, rubber)
//! material = "material.toml"    # a path (relative to this file) ...
//!
//! [material]                    # ... or the material inline, as in material.toml
//! model = "linear"
//! young_pa = 1.0e6
//! poisson = 0.45
//!
//! [mesh]                        # at most one of edge_length_m, nodes, accuracy
//! edge_length_m = 0.002         # target edge length, m
//! nodes = 2000                  # or about this many nodes solved
//! accuracy = 0.005              # or the relative height error wanted (disc)
//! symmetry = true               # disc: 60 degree sector, rectangle: quarter, with mirror planes
//! corners = ["II", "I", "I"]    # sphere-segment: topology at corners a, b, c
//!
//! # sheet only: length_m (away from the clamped edge), width_m, and
//! [[load]]
//! at = "corner"                 # middle | corner of the free edge
//! force_n = [0.0, 0.0, -1.0]
//! ```

use std::path::{Path, PathBuf};

use nalgebra::{Point3, Vector3};
use serde::Deserialize;

use super::SimError;
use super::mesh::{self, Corner, Mesh};
use super::springs::{Membrane, SpringModel};
use crate::io::InputError;
use crate::material::Material;

mod predictors;
pub use predictors::*;

mod sizing;
pub use sizing::*;

/// Default density, kg/m^3 (natural rubber 910-1100; latex about 960-1000).
pub const DEFAULT_DENSITY_KG_M3: f64 = 1100.0;

/// Hencky's coefficient `K(nu)` of the clamped disc's centre deflection
/// `w0 = K a (p a / (E t))^(1/3)` (Hencky 1915, with the computational error
/// of his series corrected by Chien 1948), tabulated at eight Poisson ratios
/// and linearly interpolated between them (within 0.25 % of the exact value;
/// used for the first guess only).
pub fn hencky_k(nu: f64) -> f64 {
    const T: [(f64, f64); 8] = [
        (0.0, 0.71832),
        (0.25, 0.66579),
        (0.3, 0.65344),
        (1.0 / 3.0, 0.64478),
        (0.4, 0.62626),
        (0.45, 0.61117),
        (0.49, 0.59824),
        (0.5, 0.59488),
    ];
    let nu = nu.clamp(0.0, 0.5);
    for w in T.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if nu <= x1 {
            return y0 + (y1 - y0) * (nu - x0) / (x1 - x0);
        }
    }
    T[7].1
}

/// The geometry of a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SceneKind {
    /// Clamped circular membrane.
    Disc {
        /// Free radius a, m.
        radius_m: f64,
        /// Height of the stress-free shape over the clamp, m: 0 for a flat
        /// disc, else a slack membrane whose reference is a spherical cap.
        dome_height_m: f64,
    },
    /// Clamped elliptical window (the whole ellipse is meshed).
    Ellipse {
        /// Semi-axes along x and y, m.
        semi_axes_m: [f64; 2],
    },
    /// Clamped rectangular window `|x| <= L/2`, `|y| <= W/2`.
    Rectangle {
        /// Along x, m.
        length_m: f64,
        /// Along y, m.
        width_m: f64,
    },
    /// Tudruj et al.'s (2023) sphere octant.
    SphereSegment {
        /// Rest radius R0, m.
        radius_m: f64,
    },
    /// Rectangle clamped on its edge x = 0.
    Sheet {
        /// Along x, m.
        length_m: f64,
        /// Along y, m.
        width_m: f64,
    },
}

impl SceneKind {
    /// The name in scene files.
    pub fn name(&self) -> &'static str {
        match self {
            SceneKind::Disc { .. } => "disc",
            SceneKind::Ellipse { .. } => "ellipse",
            SceneKind::Rectangle { .. } => "rectangle",
            SceneKind::SphereSegment { .. } => "sphere-segment",
            SceneKind::Sheet { .. } => "sheet",
        }
    }
}

/// How fine the mesh is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MeshSize {
    /// Target edge length, m.
    EdgeLength(f64),
    /// About this many nodes solved.
    Nodes(usize),
    /// Relative height error wanted (disc; see [`disc_rings_for_accuracy`]).
    Accuracy(f64),
}

/// Mesh settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshSettings {
    /// Size; `None` takes the scene's default.
    pub size: Option<MeshSize>,
    /// Disc: solve the 60 degree sector (default true).
    pub symmetry: bool,
    /// Sphere: corner topologies at a, b, c (default II, I, I as in Fig. 7).
    pub corners: [Corner; 3],
    /// Largest mesh built, nodes (default [`DEFAULT_MAX_NODES`]): a bigger
    /// one is refused before it is built, with its memory estimate.
    pub max_nodes: usize,
}

/// Default node limit of a mesh: Newton's sparse factorisation takes about
/// 33 kB per node (3.3 GB at 1e5 nodes), so 3e5 nodes is about 10 GB.
pub const DEFAULT_MAX_NODES: usize = 300_000;

impl Default for MeshSettings {
    fn default() -> Self {
        MeshSettings {
            size: None,
            symmetry: true,
            corners: [Corner::TypeII, Corner::TypeI, Corner::TypeI],
            max_nodes: DEFAULT_MAX_NODES,
        }
    }
}

impl MeshSettings {
    /// Refuses a mesh of `nodes` nodes above the limit, with its memory.
    pub fn check_nodes(&self, nodes: usize) -> Result<(), SimError> {
        if nodes > self.max_nodes {
            return Err(SimError::BadParameter(format!(
                "the mesh would have about {nodes} nodes (about {:.1} GB for Newton's factorisation), above the limit of {} nodes: ask for fewer nodes, a longer edge or a looser accuracy, or raise the node limit",
                nodes as f64 * 33e3 / 1e9,
                self.max_nodes
            )));
        }
        Ok(())
    }
}

/// A load on a named node of the sheet.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodeLoad {
    /// Probe name: `middle` or `corner` (of the free edge).
    pub at: String,
    /// Force, N.
    pub force_n: [f64; 3],
}

/// A validated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Geometry.
    pub kind: SceneKind,
    /// Thickness, m.
    pub thickness_m: f64,
    /// Pressures to solve, Pa, in order.
    pub pressures_pa: Vec<f64>,
    /// Material.
    pub material: Material,
    /// Density, kg/m^3.
    pub density_kg_m3: f64,
    /// Mesh settings.
    pub mesh: MeshSettings,
    /// Nodal loads (sheet).
    pub loads: Vec<NodeLoad>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    kind: String,
    radius_m: Option<f64>,
    semi_axes_m: Option<[f64; 2]>,
    /// Disc only: the stress-free dome height of a slack membrane, m.
    prebulge_height_m: Option<f64>,
    length_m: Option<f64>,
    width_m: Option<f64>,
    thickness_m: f64,
    #[serde(default)]
    pressure_pa: Vec<toml::Value>,
    material: toml::Value,
    density_kg_m3: Option<f64>,
    #[serde(default)]
    mesh: MeshFile,
    #[serde(default)]
    load: Vec<NodeLoad>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshFile {
    edge_length_m: Option<f64>,
    nodes: Option<usize>,
    accuracy: Option<f64>,
    symmetry: Option<bool>,
    corners: Option<Vec<String>>,
}

/// What is wrong with a scene.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// No pressure where one is needed.
    #[error("the pressure list is empty: give at least one pressure in Pa, e.g. [5000, 7300]")]
    NoPressure,
    /// A pressure that is not a positive number of Pa (1-based position).
    #[error(
        "pressure {index} of the list is {value}: every pressure must be a positive number of Pa"
    )]
    Pressure {
        /// 1-based position in the list.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A pressure that does not parse as a number (1-based position).
    #[error(
        "pressure {index} is `{text}`, not a number: write positive pressures in Pa separated by commas, e.g. 5000,7300,8940"
    )]
    NotANumber {
        /// 1-based position in the list.
        index: usize,
        /// The text.
        text: String,
    },
    /// A number out of its range.
    #[error("{key} = {value} must be {what}")]
    Value {
        /// The key.
        key: &'static str,
        /// The value.
        value: f64,
        /// Its range, and an example.
        what: &'static str,
    },
    /// A `[[load]]` that cannot be applied.
    #[error("[[load]] {0}")]
    Load(String),
    /// A `[mesh]` table that cannot be meshed.
    #[error("[mesh] {0}")]
    Mesh(String),
}

/// Checks a pressure list: non-empty, every value a finite number > 0.
pub fn validate_pressures(p: &[f64]) -> Result<(), SceneError> {
    if p.is_empty() {
        return Err(SceneError::NoPressure);
    }
    for (i, v) in p.iter().enumerate() {
        if !(v.is_finite() && *v > 0.0) {
            return Err(SceneError::Pressure {
                index: i + 1,
                value: *v,
            });
        }
    }
    Ok(())
}

/// Parses a comma-separated pressure list (`5000,7300,8940`).
pub fn parse_pressures(s: &str) -> Result<Vec<f64>, SceneError> {
    let mut out = Vec::new();
    for (i, part) in s.split(',').enumerate() {
        let v: f64 = part.trim().parse().map_err(|_| SceneError::NotANumber {
            index: i + 1,
            text: part.trim().to_string(),
        })?;
        out.push(v);
    }
    validate_pressures(&out)?;
    Ok(out)
}

fn parse_corner(s: &str) -> Option<Corner> {
    match s.trim() {
        "I" | "1" => Some(Corner::TypeI),
        "II" | "2" => Some(Corner::TypeII),
        _ => None,
    }
}

impl MeshSettings {
    fn from_file(m: &MeshFile) -> Result<MeshSettings, SceneError> {
        let given = [
            m.edge_length_m.is_some(),
            m.nodes.is_some(),
            m.accuracy.is_some(),
        ]
        .iter()
        .filter(|b| **b)
        .count();
        if given > 1 {
            return Err(SceneError::Mesh(
                "give at most one of edge_length_m, nodes, accuracy".into(),
            ));
        }
        let size = if let Some(h) = m.edge_length_m {
            Some(MeshSize::EdgeLength(h))
        } else if let Some(n) = m.nodes {
            Some(MeshSize::Nodes(n))
        } else {
            m.accuracy.map(MeshSize::Accuracy)
        };
        let mut s = MeshSettings {
            size,
            ..MeshSettings::default()
        };
        if let Some(sym) = m.symmetry {
            s.symmetry = sym;
        }
        if let Some(c) = &m.corners {
            if c.len() != 3 {
                return Err(SceneError::Mesh(format!(
                    "corners = {c:?}: give three, for corners a, b, c, each \"I\" or \"II\""
                )));
            }
            for (k, name) in c.iter().enumerate() {
                s.corners[k] = parse_corner(name).ok_or_else(|| {
                    SceneError::Mesh(format!(
                        "corners: `{name}` is not a corner type; write \"I\" or \"II\""
                    ))
                })?;
            }
        }
        s.validate()?;
        Ok(s)
    }

    /// Checks the size.
    pub fn validate(&self) -> Result<(), SceneError> {
        match self.size {
            Some(MeshSize::EdgeLength(h)) if !(h.is_finite() && h > 0.0) => {
                Err(SceneError::Value {
                    key: "edge_length_m",
                    value: h,
                    what: "a positive length in metres",
                })
            }
            Some(MeshSize::Nodes(n)) if n < 3 => Err(SceneError::Mesh(format!(
                "nodes = {n}: ask for at least 3 nodes"
            ))),
            Some(MeshSize::Accuracy(a)) if !(a.is_finite() && a > 0.0 && a < 0.5) => {
                Err(SceneError::Value {
                    key: "accuracy",
                    value: a,
                    what: "a relative error in (0, 0.5), e.g. 0.005 for 0.5 %",
                })
            }
            _ => Ok(()),
        }
    }
}

impl Scene {
    /// Reads a scene file; paths in it are relative to its folder.
    pub fn read(path: impl AsRef<Path>) -> Result<Scene, InputError> {
        let path = path.as_ref();
        let f: SceneFile = crate::io::read_toml(path)?;
        let err = |m: String| InputError::file(path, m);
        let base = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        let material = match &f.material {
            toml::Value::String(p) => {
                let mp = if Path::new(p).is_absolute() {
                    PathBuf::from(p)
                } else {
                    base.join(p)
                };
                Material::read(&mp)?
            }
            toml::Value::Table(t) => {
                Material::from_table(t).map_err(|e| err(format!("[material]: {e}")))?
            }
            other => {
                return Err(err(format!(
                    "material = {other}: give a path to a material.toml or a [material] table"
                )));
            }
        };
        let mut pressures = Vec::new();
        for (i, v) in f.pressure_pa.iter().enumerate() {
            let p = match v {
                toml::Value::Integer(k) => *k as f64,
                toml::Value::Float(x) => *x,
                other => {
                    return Err(err(format!(
                        "pressure_pa entry {} is {other}: every pressure must be a positive number of Pa",
                        i + 1
                    )));
                }
            };
            pressures.push(p);
        }
        let need = |v: Option<f64>, name: &str| {
            v.ok_or_else(|| err(format!("kind = \"{}\" needs {name} (m)", f.kind)))
        };
        let kind = match f.kind.as_str() {
            "disc" => SceneKind::Disc {
                radius_m: need(f.radius_m, "radius_m")?,
                dome_height_m: f.prebulge_height_m.unwrap_or(0.0),
            },
            "ellipse" => SceneKind::Ellipse {
                semi_axes_m: f.semi_axes_m.ok_or_else(|| {
                    err("kind = \"ellipse\" needs semi_axes_m = [a, b] (m), the semi-axes along x and y".into())
                })?,
            },
            "rectangle" => SceneKind::Rectangle {
                length_m: need(f.length_m, "length_m")?,
                width_m: need(f.width_m, "width_m")?,
            },
            "sphere-segment" => SceneKind::SphereSegment {
                radius_m: need(f.radius_m, "radius_m")?,
            },
            "sheet" => SceneKind::Sheet {
                length_m: need(f.length_m, "length_m")?,
                width_m: need(f.width_m, "width_m")?,
            },
            other => {
                return Err(err(format!(
                    "kind = \"{other}\" is not a scene; write \"disc\", \"ellipse\", \"rectangle\", \"sphere-segment\" or \"sheet\""
                )));
            }
        };
        let scene = Scene {
            kind,
            thickness_m: f.thickness_m,
            pressures_pa: pressures,
            material,
            density_kg_m3: f.density_kg_m3.unwrap_or(DEFAULT_DENSITY_KG_M3),
            mesh: MeshSettings::from_file(&f.mesh).map_err(|e| err(e.to_string()))?,
            loads: f.load,
        };
        scene.validate(false).map_err(|e| err(e.to_string()))?;
        Ok(scene)
    }

    /// Whether the scene needs a pressure list: every scene but a sheet
    /// with nodal loads, which its loads alone can deform.
    pub fn needs_pressures(&self) -> bool {
        !matches!(self.kind, SceneKind::Sheet { .. }) || self.loads.is_empty()
    }

    /// The pressures to solve at: the list, or one state at pressure 0
    /// under the nodal loads alone when there is no list.
    pub fn pressures_to_solve(&self) -> Vec<f64> {
        if self.pressures_pa.is_empty() && !self.loads.is_empty() {
            vec![0.0]
        } else {
            self.pressures_pa.clone()
        }
    }

    /// Checks lengths, loads and (when `need_pressures`) the pressure list.
    pub fn validate(&self, need_pressures: bool) -> Result<(), SceneError> {
        let pos = |v: f64, key: &'static str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(SceneError::Value {
                    key,
                    value: v,
                    what: "a positive length in metres",
                })
            }
        };
        match self.kind {
            SceneKind::Disc {
                radius_m,
                dome_height_m,
            } => {
                pos(radius_m, "radius_m")?;
                if !(dome_height_m.is_finite() && (0.0..radius_m).contains(&dome_height_m)) {
                    return Err(SceneError::Value {
                        key: "prebulge_height_m",
                        value: dome_height_m,
                        what: "zero or a positive height below radius_m, in metres",
                    });
                }
            }
            SceneKind::SphereSegment { radius_m } => pos(radius_m, "radius_m")?,
            SceneKind::Ellipse { semi_axes_m } => {
                pos(semi_axes_m[0], "semi_axes_m")?;
                pos(semi_axes_m[1], "semi_axes_m")?;
            }
            SceneKind::Rectangle { length_m, width_m } | SceneKind::Sheet { length_m, width_m } => {
                pos(length_m, "length_m")?;
                pos(width_m, "width_m")?;
            }
        }
        pos(self.thickness_m, "thickness_m")?;
        if !(self.density_kg_m3.is_finite() && self.density_kg_m3 > 0.0) {
            return Err(SceneError::Value {
                key: "density_kg_m3",
                value: self.density_kg_m3,
                what: "positive (kg/m^3)",
            });
        }
        let nu = self.material.poisson;
        if !(nu.is_finite() && (0.0..0.5).contains(&nu)) {
            return Err(SceneError::Value {
                key: "poisson",
                value: nu,
                what: "in [0, 0.5): the plane-stress spring formulas divide by 1 - nu^2 and 1 - nu",
            });
        }
        for l in &self.loads {
            if !matches!(self.kind, SceneKind::Sheet { .. }) {
                return Err(SceneError::Load("is only for kind = \"sheet\"".into()));
            }
            if l.at != "middle" && l.at != "corner" {
                return Err(SceneError::Load(format!(
                    "at = \"{}\": write \"middle\" or \"corner\"",
                    l.at
                )));
            }
            if l.force_n.iter().any(|v| !v.is_finite()) {
                return Err(SceneError::Load(format!(
                    "force_n = {:?} must be finite (N)",
                    l.force_n
                )));
            }
        }
        if need_pressures || !self.pressures_pa.is_empty() {
            validate_pressures(&self.pressures_pa)?;
        }
        self.mesh.validate()
    }

    /// The disc of an experiment's specimen.
    pub fn from_specimen(
        spec: &crate::experiment::Specimen,
        material: Material,
        pressures_pa: Vec<f64>,
    ) -> Scene {
        Scene {
            kind: SceneKind::Disc {
                radius_m: spec.radius_m,
                dome_height_m: spec.prebulge_height_m,
            },
            thickness_m: spec.thickness_m,
            pressures_pa,
            material,
            density_kg_m3: DEFAULT_DENSITY_KG_M3,
            mesh: MeshSettings::default(),
            loads: Vec::new(),
        }
    }

    /// The specimen's window (an experiment's `[window]`): the disc for a
    /// circle, else the ellipse or rectangle of the same thickness.
    pub fn from_window(
        spec: &crate::experiment::Specimen,
        window: &crate::experiment::Window,
        material: Material,
        pressures_pa: Vec<f64>,
    ) -> Scene {
        use crate::experiment::Window;
        let mut s = Scene::from_specimen(spec, material, pressures_pa);
        match *window {
            Window::Circle => {}
            Window::Ellipse { semi_axes_m } => s.kind = SceneKind::Ellipse { semi_axes_m },
            Window::Rectangle { length_m, width_m } => {
                s.kind = SceneKind::Rectangle { length_m, width_m }
            }
        }
        s
    }

    /// Builds the mesh (a requested accuracy is met for every spring model).
    pub fn build_mesh(&self) -> Result<Mesh, SimError> {
        self.build_mesh_for(&[])
    }

    /// Builds the mesh; a requested accuracy is met for the given models.
    pub fn build_mesh_for(&self, models: &[SpringModel]) -> Result<Mesh, SimError> {
        match self.kind {
            SceneKind::Disc {
                radius_m,
                dome_height_m,
            } => {
                let sector = self.mesh.symmetry;
                let rings = match self.mesh.size {
                    Some(MeshSize::EdgeLength(h)) => (radius_m / h).ceil() as usize,
                    Some(MeshSize::Nodes(n)) => mesh::disc_rings_for_nodes(n, sector),
                    Some(MeshSize::Accuracy(a)) => disc_rings_for_accuracy(a, models),
                    None => DEFAULT_DISC_RINGS,
                }
                .max(1);
                let n = if sector {
                    (rings + 1) * (rings + 2) / 2
                } else {
                    1 + 3 * rings * (rings + 1)
                };
                self.mesh.check_nodes(n)?;
                disc_mesh(radius_m, dome_height_m, rings, sector)
            }
            SceneKind::SphereSegment { radius_m } => {
                let n = match self.mesh.size {
                    Some(MeshSize::EdgeLength(h)) => {
                        (std::f64::consts::FRAC_PI_2 * radius_m / h).ceil() as usize
                    }
                    Some(MeshSize::Nodes(n)) => {
                        (((8.0 * n as f64 + 1.0).sqrt() - 3.0) / 2.0).round() as usize
                    }
                    Some(MeshSize::Accuracy(_)) | None => DEFAULT_SPHERE_DIVISIONS,
                }
                .max(2);
                self.mesh.check_nodes((n + 1) * (n + 2) / 2)?;
                mesh::sphere_segment(mesh::SphereOptions {
                    radius_m,
                    divisions: n,
                    corners: self.mesh.corners,
                })
            }
            SceneKind::Ellipse {
                semi_axes_m: [a, b],
            } => {
                let rings = match self.mesh.size {
                    Some(MeshSize::EdgeLength(h)) => ((a * b).sqrt() / h).ceil() as usize,
                    Some(MeshSize::Nodes(n)) => mesh::disc_rings_for_nodes(n, false),
                    Some(MeshSize::Accuracy(_)) | None => DEFAULT_ELLIPSE_RINGS,
                }
                .max(1);
                self.mesh.check_nodes(1 + 3 * rings * (rings + 1))?;
                mesh::ellipse(a, b, rings)
            }
            SceneKind::Rectangle { length_m, width_m } => {
                let quarter = self.mesh.symmetry;
                let share = if quarter { 0.25 } else { 1.0 };
                let half_cells = match self.mesh.size {
                    Some(MeshSize::EdgeLength(h)) => (width_m / (2.0 * h)).ceil(),
                    // about L W / h^2 nodes in the whole, h = W / (2 n)
                    Some(MeshSize::Nodes(n)) => (n as f64 / share * width_m / (4.0 * length_m))
                        .sqrt()
                        .round(),
                    Some(MeshSize::Accuracy(_)) | None => DEFAULT_RECTANGLE_HALF_CELLS as f64,
                }
                .clamp(1.0, 1e9) as usize;
                let h = width_m / (2.0 * half_cells as f64);
                let nodes = share * (length_m / h + 1.0) * (width_m / h + 1.0);
                self.mesh.check_nodes(nodes.min(1e18) as usize)?;
                mesh::rectangle(mesh::RectangleOptions {
                    length_m,
                    width_m,
                    half_cells,
                    quarter,
                })
            }
            SceneKind::Sheet { length_m, width_m } => {
                let h = match self.mesh.size {
                    Some(MeshSize::EdgeLength(h)) => h,
                    Some(MeshSize::Nodes(n)) => {
                        (length_m * width_m * 2.0 / (3f64.sqrt() * n as f64)).sqrt()
                    }
                    Some(MeshSize::Accuracy(_)) | None => length_m.min(width_m) / 10.0,
                };
                let n = (length_m * width_m * 2.0 / (3f64.sqrt() * h * h)).min(1e18);
                self.mesh.check_nodes(n as usize)?;
                mesh::sheet(mesh::SheetOptions {
                    length_m,
                    width_m,
                    edge_length_m: h,
                })
            }
        }
    }

    /// The membrane of this scene's material, thickness, density and nodal
    /// loads on `mesh`, with the spring model `model`.
    pub fn membrane(&self, mesh: &Mesh, model: SpringModel) -> Result<Membrane, SimError> {
        let mut m = Membrane::new(
            mesh,
            model,
            &self.material,
            self.thickness_m,
            self.density_kg_m3,
        )?;
        m.node_loads = self.node_loads(mesh);
        Ok(m)
    }

    /// The nodal loads of the scene on a mesh.
    pub fn node_loads(&self, mesh: &Mesh) -> Vec<(usize, Vector3<f64>)> {
        self.loads
            .iter()
            .filter_map(|l| mesh.probe(&l.at).map(|n| (n, Vector3::from(l.force_n))))
            .collect()
    }

    /// Names of the extra output columns of this scene (after the common ones).
    pub fn extra_columns(&self) -> Vec<&'static str> {
        match self.kind {
            SceneKind::SphereSegment { .. } => vec![
                "radius_mean_m",
                "radius_min_m",
                "radius_max_m",
                "radius_centre_m",
                "radius_corner_a_m",
                "radius_corner_b_m",
                "radius_corner_c_m",
            ],
            _ => vec![],
        }
    }

    /// The reported height and the extra columns at positions `x`.
    ///
    /// * disc: `height_m` = apex height above the clamp plane;
    /// * sphere segment: `height_m` = growth of the mean radius `R - R0`;
    ///   radii are node distances from the centre (mean over all nodes, min,
    ///   max, at the centre point P of the segment and at the corners);
    /// * sheet: `height_m` = displacement magnitude of the first loaded node
    ///   (else of the middle of the free edge).
    pub fn measure(&self, mesh: &Mesh, x: &[Point3<f64>]) -> (f64, Vec<f64>) {
        match self.kind {
            SceneKind::Disc { .. } | SceneKind::Ellipse { .. } | SceneKind::Rectangle { .. } => {
                (x[mesh.probe("apex").unwrap_or(0)].z, vec![])
            }
            SceneKind::SphereSegment { radius_m } => {
                let r: Vec<f64> = x.iter().map(|p| p.coords.norm()).collect();
                let mean = r.iter().sum::<f64>() / r.len() as f64;
                let min = r.iter().cloned().fold(f64::INFINITY, f64::min);
                let max = r.iter().cloned().fold(0.0, f64::max);
                let at = |name: &str| mesh.probe(name).map(|i| r[i]).unwrap_or(f64::NAN);
                (
                    mean - radius_m,
                    vec![
                        mean,
                        min,
                        max,
                        at("centre"),
                        at("corner_a"),
                        at("corner_b"),
                        at("corner_c"),
                    ],
                )
            }
            SceneKind::Sheet { .. } => {
                let node = self
                    .loads
                    .first()
                    .and_then(|l| mesh.probe(&l.at))
                    .or_else(|| mesh.probe("middle"))
                    .unwrap_or(0);
                ((x[node] - mesh.nodes[node]).norm(), vec![])
            }
        }
    }
}

#[cfg(test)]
mod tests;
