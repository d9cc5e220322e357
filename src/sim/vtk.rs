//! Deformed meshes as legacy ASCII VTK (`POLYDATA`), which ParaView opens
//! directly: points, triangles, the displacement per node and the area
//! stretch `sqrt(|T| / |T0|)` per triangle.

use std::fmt::Write;

use nalgebra::Point3;

use super::mesh::Mesh;

/// The VTK text of a mesh at positions `x`, with a title line.
pub fn polydata(mesh: &Mesh, x: &[Point3<f64>], stretch: &[f64], title: &str) -> String {
    let mut s = String::new();
    let title: String = title.chars().filter(|c| *c != '\n').take(250).collect();
    let _ = writeln!(
        s,
        "# vtk DataFile Version 3.0\n{title}\nASCII\nDATASET POLYDATA"
    );
    let _ = writeln!(s, "POINTS {} double", x.len());
    for p in x {
        let _ = writeln!(s, "{} {} {}", p.x, p.y, p.z);
    }
    let nt = mesh.triangles.len();
    let _ = writeln!(s, "POLYGONS {} {}", nt, 4 * nt);
    for t in &mesh.triangles {
        let _ = writeln!(s, "3 {} {} {}", t[0], t[1], t[2]);
    }
    let _ = writeln!(s, "POINT_DATA {}\nVECTORS displacement_m double", x.len());
    for (p, p0) in x.iter().zip(&mesh.nodes) {
        let d = p - p0;
        let _ = writeln!(s, "{} {} {}", d.x, d.y, d.z);
    }
    let _ = writeln!(
        s,
        "CELL_DATA {nt}\nSCALARS area_stretch double 1\nLOOKUP_TABLE default"
    );
    for v in stretch {
        let _ = writeln!(s, "{v}");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::mesh::{DiscOptions, disc};

    #[test]
    fn counts_match_the_mesh() {
        let m = disc(DiscOptions {
            radius_m: 1.0,
            rings: 3,
            sector: true,
        })
        .unwrap();
        let st = vec![1.0; m.triangles.len()];
        let s = polydata(&m, &m.nodes, &st, "t");
        assert!(s.contains(&format!("POINTS {} double", m.nodes.len())));
        assert!(s.contains(&format!(
            "POLYGONS {} {}",
            m.triangles.len(),
            4 * m.triangles.len()
        )));
        assert_eq!(
            s.lines().count(),
            5 + m.nodes.len() + 1 + m.triangles.len() + 2 + m.nodes.len() + 3 + m.triangles.len()
        );
    }
}
