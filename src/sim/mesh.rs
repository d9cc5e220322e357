//! Triangle meshes of the scenes: the clamped disc (full, or the 60 degree
//! sector with mirror planes on its cut edges), the sphere segment of
//! Tudruj et al. (2023) section 4 (an octant with three symmetry planes, corner topologies of
//! its Fig. 7) and the sheet clamped on one edge (Sudhamani & Merriliance's (2019) experiments).
//!
//! A [`Mesh`] is plain data: reference node positions, triangles (counter-
//! clockwise seen from the side the pressure pushes towards), the unique
//! edges, and one [`Constraint`] per node. Solvers borrow it.
//!
//! ## The disc: hexagonal rings
//! Ring `k` (`k = 0..=n`) holds `6k` nodes at radius `a k / n`, equally spaced
//! in angle; the band between rings `k` and `k+1` is triangulated like the
//! equilateral lattice (`2k + 1` triangles per sixth). All triangles are
//! acute: angles from 43.8 to `90 - 30/n` degrees (the largest beside the six
//! spokes, where a radial edge meets a ring chord; n = 100: 43.8-89.7).
//! Laplacian smoothing was tried and made the smallest angle worse (20 deg).
//! The full disc is mirror-symmetric about every spoke at a multiple of 30
//! degrees that carries nodes, so one sixth (0 to 60 degrees) with its cut-edge
//! nodes held on the two mirror planes is the same problem with 1/6 of the
//! nodes ([`DiscOptions::sector`], the default).
//!
//! ## The sphere segment
//! The octant `x, y, z >= 0` of a sphere, meshed by subdividing the flat
//! octahedron face into `n^2` triangles and projecting the nodes onto the
//! sphere; nodes on the planes `x = 0`, `y = 0`, `z = 0` slide on them. Corner
//! topologies (Tudruj et al. (2023) Fig. 7, whose picture is not in the text; bulge's
//! reading): type I, one triangle holds the 90 degree corner; type II, the edge
//! facing the corner is flipped so that two triangles share the corner
//! (45 + 45 degrees). Corner a is the pole (0, 0, R), b is (R, 0, 0), c is
//! (0, R, 0). Near the corners the projection turns the equilateral pattern
//! into right isosceles triangles: the quality report counts them.

use nalgebra::{Point3, Vector3};

use super::SimError;

/// How a node may move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Constraint {
    /// Free in all three directions.
    Free,
    /// Slides on a plane (mirror symmetry) with this unit normal.
    Plane(Vector3<f64>),
    /// Slides along a line (two mirror planes) with this unit direction.
    Line(Vector3<f64>),
    /// Clamped.
    Fixed,
}

impl Constraint {
    /// Removes the constrained components of a force or velocity.
    #[inline]
    pub fn project(&self, v: Vector3<f64>) -> Vector3<f64> {
        match self {
            Constraint::Free => v,
            Constraint::Plane(n) => v - n * n.dot(&v),
            Constraint::Line(d) => d * d.dot(&v),
            Constraint::Fixed => Vector3::zeros(),
        }
    }

    /// An orthonormal basis of the directions the node may move in (0 to 3
    /// vectors), for the reduced Newton system.
    pub fn free_basis(&self) -> Vec<Vector3<f64>> {
        match self {
            Constraint::Free => vec![Vector3::x(), Vector3::y(), Vector3::z()],
            Constraint::Plane(n) => {
                let a = if n.x.abs() < 0.9 {
                    Vector3::x()
                } else {
                    Vector3::y()
                };
                let u = (a - n * n.dot(&a)).normalize();
                let v = n.cross(&u);
                vec![u, v]
            }
            Constraint::Line(d) => vec![*d],
            Constraint::Fixed => vec![],
        }
    }

    /// Adds a plane constraint to this one.
    fn and_plane(self, n: Vector3<f64>) -> Constraint {
        match self {
            Constraint::Free => Constraint::Plane(n),
            Constraint::Plane(m) => {
                let d = m.cross(&n);
                if d.norm() < 1e-12 {
                    Constraint::Plane(m)
                } else {
                    Constraint::Line(d.normalize())
                }
            }
            Constraint::Line(d) => {
                if d.dot(&n).abs() < 1e-12 {
                    Constraint::Line(d)
                } else {
                    Constraint::Fixed
                }
            }
            Constraint::Fixed => Constraint::Fixed,
        }
    }
}

/// A named node whose position the scene reports (apex, corners).
#[derive(Debug, Clone, PartialEq)]
pub struct Probe {
    /// Short name used in column names (`apex`, `corner_a`, ...).
    pub name: String,
    /// Node index.
    pub node: usize,
}

/// A triangle mesh with per-node constraints. Plain data.
#[derive(Debug, Clone)]
pub struct Mesh {
    /// Reference (stress-free) node positions, m.
    pub nodes: Vec<Point3<f64>>,
    /// Triangles as node indices, counter-clockwise about the pressure side.
    pub triangles: Vec<[u32; 3]>,
    /// Unique edges `[i, j]` with `i < j`.
    pub edges: Vec<[u32; 2]>,
    /// For each triangle, the edge opposite each of its three vertices.
    pub triangle_edges: Vec<[u32; 3]>,
    /// One constraint per node.
    pub constraints: Vec<Constraint>,
    /// Nodes the scene reports.
    pub probes: Vec<Probe>,
    /// Number of copies of this mesh that make the whole body (6 for the disc
    /// sector, 8 for the sphere octant, 1 otherwise): reported node counts
    /// stay those actually solved.
    pub symmetry_copies: usize,
}

/// Angles and shapes of a mesh's triangles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quality {
    /// Number of triangles.
    pub triangles: usize,
    /// Smallest angle, degrees.
    pub min_angle_deg: f64,
    /// Largest angle, degrees.
    pub max_angle_deg: f64,
    /// Share of triangles with an angle of 90 degrees or more (to 1e-9 rad).
    pub non_acute_share: f64,
    /// Shortest and longest edge, m.
    pub edge_range_m: [f64; 2],
}

impl Mesh {
    /// Builds a mesh from nodes, triangles and constraints, and checks it:
    /// indices in range, no degenerate triangle (area below 1e-10 of its
    /// longest side squared), and a consistent orientation (every interior edge
    /// is run once in each direction, so a flipped triangle is caught).
    pub fn new(
        nodes: Vec<Point3<f64>>,
        triangles: Vec<[u32; 3]>,
        constraints: Vec<Constraint>,
    ) -> Result<Mesh, SimError> {
        if constraints.len() != nodes.len() {
            return Err(SimError::BadMesh(format!(
                "{} constraints for {} nodes",
                constraints.len(),
                nodes.len()
            )));
        }
        if triangles.is_empty() {
            return Err(SimError::BadMesh("the mesh has no triangles".into()));
        }
        for (t, tri) in triangles.iter().enumerate() {
            for &i in tri {
                if i as usize >= nodes.len() {
                    return Err(SimError::BadMesh(format!(
                        "triangle {t} refers to node {i}, but there are only {} nodes",
                        nodes.len()
                    )));
                }
            }
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                return Err(SimError::DegenerateTriangle {
                    triangle: t,
                    nodes: *tri,
                    area_m2: 0.0,
                });
            }
            let p = tri.map(|i| nodes[i as usize]);
            let area = (p[1] - p[0]).cross(&(p[2] - p[0])).norm() / 2.0;
            let longest = (0..3)
                .map(|k| (p[(k + 1) % 3] - p[k]).norm())
                .fold(0.0_f64, f64::max);
            if area.is_nan() || area <= 1e-10 * longest * longest {
                return Err(SimError::DegenerateTriangle {
                    triangle: t,
                    nodes: *tri,
                    area_m2: area,
                });
            }
        }
        // Edges and orientation.
        let mut half: Vec<(u32, u32, usize, usize)> = Vec::with_capacity(3 * triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (i, j) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
                half.push((i.min(j), i.max(j), t, k));
            }
        }
        half.sort_unstable();
        let mut edges = Vec::new();
        let mut triangle_edges = vec![[0u32; 3]; triangles.len()];
        let mut s = 0;
        while s < half.len() {
            let mut e = s + 1;
            while e < half.len() && half[e].0 == half[s].0 && half[e].1 == half[s].1 {
                e += 1;
            }
            if e - s > 2 {
                return Err(SimError::BadMesh(format!(
                    "edge {}-{} is shared by {} triangles; a membrane mesh allows at most 2",
                    half[s].0,
                    half[s].1,
                    e - s
                )));
            }
            if e - s == 2 {
                let dir = |h: &(u32, u32, usize, usize)| {
                    triangles[h.2][(h.3 + 1) % 3] < triangles[h.2][(h.3 + 2) % 3]
                };
                if dir(&half[s]) == dir(&half[s + 1]) {
                    let t = half[s + 1].2;
                    return Err(SimError::InvertedTriangle {
                        triangle: t,
                        nodes: triangles[t],
                    });
                }
            }
            let id = edges.len() as u32;
            edges.push([half[s].0, half[s].1]);
            for h in &half[s..e] {
                triangle_edges[h.2][h.3] = id;
            }
            s = e;
        }
        Ok(Mesh {
            nodes,
            triangles,
            edges,
            triangle_edges,
            constraints,
            probes: Vec::new(),
            symmetry_copies: 1,
        })
    }

    /// Angle and edge-length statistics.
    pub fn quality(&self) -> Quality {
        let mut min_a = f64::INFINITY;
        let mut max_a = 0.0_f64;
        let mut non_acute = 0usize;
        let mut emin = f64::INFINITY;
        let mut emax = 0.0_f64;
        for tri in &self.triangles {
            let p = tri.map(|i| self.nodes[i as usize]);
            let mut tmax = 0.0_f64;
            for k in 0..3 {
                let u = p[(k + 1) % 3] - p[k];
                let v = p[(k + 2) % 3] - p[k];
                let ang = u.angle(&v);
                min_a = min_a.min(ang);
                tmax = tmax.max(ang);
                let l = u.norm();
                emin = emin.min(l);
                emax = emax.max(l);
            }
            max_a = max_a.max(tmax);
            if tmax >= std::f64::consts::FRAC_PI_2 - 1e-9 {
                non_acute += 1;
            }
        }
        Quality {
            triangles: self.triangles.len(),
            min_angle_deg: min_a.to_degrees(),
            max_angle_deg: max_a.to_degrees(),
            non_acute_share: non_acute as f64 / self.triangles.len() as f64,
            edge_range_m: [emin, emax],
        }
    }

    /// Holds every free node of a flat mesh in its plane `z = 0` (an
    /// in-plane problem such as a sheet pulled along its plane).
    pub fn hold_in_plane(&mut self) {
        for c in self.constraints.iter_mut() {
            if *c == Constraint::Free {
                *c = Constraint::Plane(nalgebra::Vector3::z());
            }
        }
    }

    /// The node index of a probe by name.
    pub fn probe(&self, name: &str) -> Option<usize> {
        self.probes.iter().find(|p| p.name == name).map(|p| p.node)
    }
}

/// Options of the disc mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscOptions {
    /// Free radius `a`, m.
    pub radius_m: f64,
    /// Number of rings `n` (edge length about `a / n`), >= 1.
    pub rings: usize,
    /// Mesh the 60 degree sector with mirror planes (default true).
    pub sector: bool,
}

/// The number of rings that gives about `nodes` solved nodes.
pub fn disc_rings_for_nodes(nodes: usize, sector: bool) -> usize {
    let n = nodes as f64;
    let r = if sector {
        // (n+1)(n+2)/2 nodes
        ((8.0 * n + 1.0).sqrt() - 3.0) / 2.0
    } else {
        // 1 + 3n(n+1) nodes
        (-3.0 + (9.0 + 12.0 * (n - 1.0)).sqrt()) / 6.0
    };
    r.round().max(1.0) as usize
}

/// Lifts a flat disc mesh of radius `a` onto the spherical cap of height
/// `h0` over the same rim (the stress-free shape of a slack membrane): a node
/// at radius `r` goes to polar angle `(r / a) theta0` on the sphere of radius
/// `R0 = (a^2 + h0^2) / (2 h0)`, `theta0 = 2 atan(h0 / a)`, so that rings
/// keep equal arc lengths from the pole. The rim, the pole and the mirror
/// planes stay where they are; the springs' rest lengths and the triangles'
/// rest areas are then those of the cap.
pub fn lift_to_cap(mesh: &mut Mesh, a: f64, h0: f64) {
    let r0 = crate::mechanics::cap_radius(a, h0);
    let theta0 = crate::mechanics::cap_half_angle(a, h0);
    for n in &mut mesh.nodes {
        let r = n.x.hypot(n.y);
        let phi = (r / a).min(1.0) * theta0;
        let rho = r0 * phi.sin();
        if r > 0.0 {
            n.x *= rho / r;
            n.y *= rho / r;
        }
        n.z = r0 * phi.cos() - (r0 - h0);
    }
}

/// The clamped disc in the plane z = 0, ring nodes of the rim clamped.
pub fn disc(o: DiscOptions) -> Result<Mesh, SimError> {
    let n = o.rings;
    if n == 0 {
        return Err(SimError::BadMesh("the disc needs at least one ring".into()));
    }
    let a = o.radius_m;
    let mut nodes = vec![Point3::origin()];
    let mut constraints = vec![Constraint::Free];
    // ring_start[k]: index of node (k, 0)
    let mut ring_start = vec![0usize];
    let sixty = std::f64::consts::PI / 3.0;
    let plane0 = Vector3::new(0.0, 1.0, 0.0); // mirror y = 0
    let plane60 = Vector3::new(-(sixty.sin()), sixty.cos(), 0.0);
    for k in 1..=n {
        ring_start.push(nodes.len());
        let r = a * k as f64 / n as f64;
        let count = if o.sector { k + 1 } else { 6 * k };
        for j in 0..count {
            let th = sixty * j as f64 / k as f64;
            nodes.push(Point3::new(r * th.cos(), r * th.sin(), 0.0));
            let mut c = if k == n {
                Constraint::Fixed
            } else {
                Constraint::Free
            };
            if o.sector && k < n {
                if j == 0 {
                    c = c.and_plane(plane0);
                }
                if j == k {
                    c = c.and_plane(plane60);
                }
            }
            constraints.push(c);
        }
    }
    if o.sector {
        // the centre lies on both planes: it moves along z only
        constraints[0] = Constraint::Line(Vector3::z());
    }
    let idx = |k: usize, j: usize| -> u32 {
        if k == 0 {
            0
        } else if o.sector {
            (ring_start[k] + j) as u32
        } else {
            (ring_start[k] + j % (6 * k)) as u32
        }
    };
    let mut tris = Vec::new();
    let sectors = if o.sector { 1 } else { 6 };
    for s in 0..sectors {
        for k in 0..n {
            for i in 0..=k {
                tris.push([
                    idx(k, s * k + i),
                    idx(k + 1, s * (k + 1) + i),
                    idx(k + 1, s * (k + 1) + i + 1),
                ]);
                if i < k {
                    tris.push([
                        idx(k, s * k + i),
                        idx(k + 1, s * (k + 1) + i + 1),
                        idx(k, s * k + i + 1),
                    ]);
                }
            }
        }
    }
    let mut m = Mesh::new(nodes, tris, constraints)?;
    m.probes.push(Probe {
        name: "apex".into(),
        node: 0,
    });
    m.symmetry_copies = sectors_copies(o.sector);
    Ok(m)
}

fn sectors_copies(sector: bool) -> usize {
    if sector { 6 } else { 1 }
}

/// The elliptical window with semi-axes `a` (along x) and `b` (along y):
/// the whole hexagonal disc of `rings` rings of unit radius, scaled by `a`
/// along x and `b` along y (an affine map: every triangle keeps its
/// neighbours; at 2:1 and 24 rings the angles lie within 23.5-122.2 degrees). The
/// rim is clamped; probe `apex` at the centre.
pub fn ellipse(a: f64, b: f64, rings: usize) -> Result<Mesh, SimError> {
    if !(a.is_finite() && b.is_finite() && a > 0.0 && b > 0.0) {
        return Err(SimError::BadMesh(format!(
            "the ellipse needs positive semi-axes, not {a} and {b} m"
        )));
    }
    let mut m = disc(DiscOptions {
        radius_m: 1.0,
        rings,
        sector: false,
    })?;
    for n in &mut m.nodes {
        n.x *= a;
        n.y *= b;
    }
    Ok(m)
}

/// Options of the rectangular window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RectangleOptions {
    /// Size along x, m.
    pub length_m: f64,
    /// Size along y, m.
    pub width_m: f64,
    /// Cells across the half-width (the edge length is about
    /// `width / (2 n)`), >= 1.
    pub half_cells: usize,
    /// Mesh the quarter `x, y >= 0` with mirror planes on `x = 0` and
    /// `y = 0` (the window is centred on the origin).
    pub quarter: bool,
}

/// The rectangular window `|x| <= L/2`, `|y| <= W/2`, clamped on its
/// four edges: a grid of square-ish cells, each cut by a diagonal that
/// alternates with the parity of the cell ("union jack"), so that the mesh
/// is mirror-symmetric about every grid line and the quarter with mirror
/// planes is the same problem as the whole. Probe `apex` at the centre.
pub fn rectangle(o: RectangleOptions) -> Result<Mesh, SimError> {
    let (l, w) = (o.length_m, o.width_m);
    if !(l.is_finite() && w.is_finite() && l > 0.0 && w > 0.0) || o.half_cells == 0 {
        return Err(SimError::BadMesh(format!(
            "the rectangle needs a positive length and width (not {l} and {w} m) and at least one cell"
        )));
    }
    let hy = w / (2.0 * o.half_cells as f64);
    let half_x = ((l / 2.0 / hy).round() as usize).max(1);
    let hx = l / (2.0 * half_x as f64);
    // grid indices: i along x, j along y
    let (i0, i1, j0, j1) = if o.quarter {
        (0, half_x as i64, 0, o.half_cells as i64)
    } else {
        (
            -(half_x as i64),
            half_x as i64,
            -(o.half_cells as i64),
            o.half_cells as i64,
        )
    };
    let nx = (i1 - i0 + 1) as usize;
    let id = |i: i64, j: i64| ((j - j0) as usize * nx + (i - i0) as usize) as u32;
    let mut nodes = Vec::new();
    let mut constraints = Vec::new();
    for j in j0..=j1 {
        for i in i0..=i1 {
            nodes.push(Point3::new(i as f64 * hx, j as f64 * hy, 0.0));
            let mut c = if i.abs() == half_x as i64 || j.abs() == o.half_cells as i64 {
                Constraint::Fixed
            } else {
                Constraint::Free
            };
            if o.quarter {
                if i == 0 {
                    c = c.and_plane(Vector3::x());
                }
                if j == 0 {
                    c = c.and_plane(Vector3::y());
                }
            }
            constraints.push(c);
        }
    }
    let mut tris = Vec::new();
    for j in j0..j1 {
        for i in i0..i1 {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j).rem_euclid(2) == 0 {
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            } else {
                tris.push([a, b, d]);
                tris.push([b, c, d]);
            }
        }
    }
    let mut m = Mesh::new(nodes, tris, constraints)?;
    m.probes.push(Probe {
        name: "apex".into(),
        node: id(0, 0) as usize,
    });
    m.symmetry_copies = if o.quarter { 4 } else { 1 };
    Ok(m)
}

/// Corner topology of the sphere segment (Tudruj et al. (2023) Fig. 7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Corner {
    /// One triangle holds the 90 degree corner.
    TypeI,
    /// Two triangles share the corner (the facing edge flipped).
    TypeII,
}

/// Options of the sphere-segment mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereOptions {
    /// Sphere radius R0, m.
    pub radius_m: f64,
    /// Divisions of each octant edge, >= 2.
    pub divisions: usize,
    /// Topology at corners a (pole), b (on x), c (on y). Paper: II, I, I.
    pub corners: [Corner; 3],
}

/// The sphere octant `x, y, z >= 0` with its three symmetry planes.
#[allow(clippy::needless_range_loop)] // (i, j) are the grid coordinates
pub fn sphere_segment(o: SphereOptions) -> Result<Mesh, SimError> {
    let n = o.divisions;
    if n < 2 {
        return Err(SimError::BadMesh(
            "the sphere segment needs at least 2 divisions per edge".into(),
        ));
    }
    // node (i, j): i steps towards b = e_x, j towards c = e_y, the rest a = e_z
    let mut id = vec![vec![0u32; n + 1]; n + 1];
    let mut nodes = Vec::new();
    let mut constraints = Vec::new();
    for i in 0..=n {
        for j in 0..=(n - i) {
            let kz = n - i - j;
            let v = Vector3::new(i as f64, j as f64, kz as f64).normalize() * o.radius_m;
            id[i][j] = nodes.len() as u32;
            nodes.push(Point3::from(v));
            let mut c = Constraint::Free;
            if i == 0 {
                c = c.and_plane(Vector3::x());
            }
            if j == 0 {
                c = c.and_plane(Vector3::y());
            }
            if kz == 0 {
                c = c.and_plane(Vector3::z());
            }
            constraints.push(c);
        }
    }
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..(n - i) {
            // up triangle (i,j),(i+1,j),(i,j+1): outward normal for e_x, e_y, e_z order
            tris.push([id[i][j], id[i + 1][j], id[i][j + 1]]);
            if i + j + 1 < n {
                tris.push([id[i + 1][j], id[i + 1][j + 1], id[i][j + 1]]);
            }
        }
    }
    // Corner flips. Corner a = (0,0): triangles (0,0),(1,0),(0,1) and (1,0),(1,1),(0,1).
    let flip = |tris: &mut Vec<[u32; 3]>, corner: u32, p: u32, q: u32, r: u32| {
        // replace [corner,p,q] + [p,r,q] by [corner,p,r] + [corner,r,q]
        let t1 = tris.iter().position(|t| is_rot(t, [corner, p, q]));
        let t2 = tris.iter().position(|t| is_rot(t, [p, r, q]));
        if let (Some(t1), Some(t2)) = (t1, t2) {
            tris[t1] = [corner, p, r];
            tris[t2] = [corner, r, q];
        }
    };
    if o.corners[0] == Corner::TypeII {
        flip(&mut tris, id[0][0], id[1][0], id[0][1], id[1][1]);
    }
    if o.corners[1] == Corner::TypeII {
        // b = (n, 0): neighbours (n-1, 1) and (n-1, 0); opposite (n-2, 1)
        flip(
            &mut tris,
            id[n][0],
            id[n - 1][1],
            id[n - 1][0],
            id[n - 2][1],
        );
    }
    if o.corners[2] == Corner::TypeII {
        // c = (0, n): neighbours (0, n-1) and (1, n-1); opposite (1, n-2)
        flip(
            &mut tris,
            id[0][n],
            id[0][n - 1],
            id[1][n - 1],
            id[1][n - 2],
        );
    }
    let centre = {
        let t = n / 3;
        id[t][t]
    };
    let mut m = Mesh::new(nodes, tris, constraints)?;
    for (name, node) in [
        ("corner_a", id[0][0]),
        ("corner_b", id[n][0]),
        ("corner_c", id[0][n]),
        ("centre", centre),
    ] {
        m.probes.push(Probe {
            name: name.into(),
            node: node as usize,
        });
    }
    m.symmetry_copies = 8;
    Ok(m)
}

fn is_rot(t: &[u32; 3], u: [u32; 3]) -> bool {
    (0..3).any(|r| t[0] == u[r] && t[1] == u[(r + 1) % 3] && t[2] == u[(r + 2) % 3])
}

/// Options of the sheet mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SheetOptions {
    /// Size along x (away from the clamped edge x = 0), m.
    pub length_m: f64,
    /// Size along y (along the clamped edge), m.
    pub width_m: f64,
    /// Target edge length, m.
    pub edge_length_m: f64,
}

/// A rectangle in z = 0, clamped on its edge x = 0. Columns of nodes parallel
/// to the clamped edge, every other column shifted by half a spacing: the
/// interior triangles are close to equilateral; the ones on the free edges
/// y = 0 and y = width are right-angled (they are counted in the quality).
pub fn sheet(o: SheetOptions) -> Result<Mesh, SimError> {
    if !(o.edge_length_m > 0.0 && o.length_m > 0.0 && o.width_m > 0.0) {
        return Err(SimError::BadMesh(
            "the sheet needs positive length, width and edge length".into(),
        ));
    }
    let ny = ((o.width_m / o.edge_length_m).round() as usize).max(1);
    let hy = o.width_m / ny as f64;
    let nx = ((o.length_m / (hy * 3f64.sqrt() / 2.0)).round() as usize).max(1);
    let hx = o.length_m / nx as f64;
    let mut nodes = Vec::new();
    let mut constraints = Vec::new();
    let mut col: Vec<Vec<u32>> = Vec::new();
    for c in 0..=nx {
        let x = c as f64 * hx;
        let mut ids = Vec::new();
        let ys: Vec<f64> = if c % 2 == 0 {
            (0..=ny).map(|j| j as f64 * hy).collect()
        } else {
            let mut v = vec![0.0];
            v.extend((0..ny).map(|j| (j as f64 + 0.5) * hy));
            v.push(o.width_m);
            v
        };
        for y in ys {
            ids.push(nodes.len() as u32);
            nodes.push(Point3::new(x, y, 0.0));
            constraints.push(if c == 0 {
                Constraint::Fixed
            } else {
                Constraint::Free
            });
        }
        col.push(ids);
    }
    let mut tris = Vec::new();
    for c in 0..nx {
        // zip two columns by y (merge), making triangles counter-clockwise (+z)
        let (l, r) = (&col[c], &col[c + 1]);
        let y = |id: u32| nodes[id as usize].y;
        let (mut i, mut j) = (0, 0);
        while i + 1 < l.len() || j + 1 < r.len() {
            let adv_left = if i + 1 >= l.len() {
                false
            } else if j + 1 >= r.len() {
                true
            } else {
                y(l[i + 1]) <= y(r[j + 1])
            };
            if adv_left {
                tris.push([l[i], r[j], l[i + 1]]);
                i += 1;
            } else {
                tris.push([l[i], r[j], r[j + 1]]);
                j += 1;
            }
        }
    }
    let mut m = Mesh::new(nodes, tris, constraints)?;
    let mid = col[nx][col[nx].len() / 2];
    let corner = *col[nx].last().expect("non-empty column");
    m.probes.push(Probe {
        name: "middle".into(),
        node: mid as usize,
    });
    m.probes.push(Probe {
        name: "corner".into(),
        node: corner as usize,
    });
    Ok(m)
}

#[cfg(test)]
mod tests;
