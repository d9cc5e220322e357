//! Tests of `mesh`.

use super::*;

#[test]
fn disc_sector_and_full_counts_and_quality() {
    for n in [1, 2, 5, 12, 40] {
        let s = disc(DiscOptions {
            radius_m: 1.0,
            rings: n,
            sector: true,
        })
        .unwrap();
        assert_eq!(s.nodes.len(), (n + 1) * (n + 2) / 2);
        assert_eq!(s.triangles.len(), n * n);
        let f = disc(DiscOptions {
            radius_m: 1.0,
            rings: n,
            sector: false,
        })
        .unwrap();
        assert_eq!(f.nodes.len(), 1 + 3 * n * (n + 1));
        assert_eq!(f.triangles.len(), 6 * n * n);
        let q = f.quality();
        assert_eq!(q.non_acute_share, 0.0, "{q:?}");
        // strictly acute; the largest angle, 90 - 30/n degrees, sits beside the spokes
        assert!(q.max_angle_deg < 90.0 && q.min_angle_deg > 43.0, "{q:?}");
        assert_eq!(disc_rings_for_nodes(s.nodes.len(), true), n);
        assert_eq!(disc_rings_for_nodes(f.nodes.len(), false), n);
    }
}

#[test]
fn sphere_corner_topologies() {
    let o = SphereOptions {
        radius_m: 1.0,
        divisions: 8,
        corners: [Corner::TypeII, Corner::TypeI, Corner::TypeI],
    };
    let m = sphere_segment(o).unwrap();
    let count = |node: usize| {
        m.triangles
            .iter()
            .filter(|t| t.contains(&(node as u32)))
            .count()
    };
    assert_eq!(count(m.probe("corner_a").unwrap()), 2);
    assert_eq!(count(m.probe("corner_b").unwrap()), 1);
    assert_eq!(count(m.probe("corner_c").unwrap()), 1);
    // outward orientation
    for t in &m.triangles {
        let p = t.map(|i| m.nodes[i as usize]);
        let n = (p[1] - p[0]).cross(&(p[2] - p[0]));
        assert!(n.dot(&p[0].coords) > 0.0);
    }
    // only the triangles at the three corners are not acute
    let q = m.quality();
    assert!(q.non_acute_share * 64.0 <= 4.0 + 1e-9, "{q:?}");
    assert!(q.max_angle_deg < 100.0, "{q:?}");
}

#[test]
fn inverted_and_degenerate_triangles_are_refused() {
    let nodes = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
        Point3::new(1.0, 1.0, 0.0),
    ];
    let c = vec![Constraint::Free; 4];
    let e = Mesh::new(nodes.clone(), vec![[0, 1, 2], [1, 2, 3]], c.clone()).unwrap_err();
    assert!(
        matches!(e, SimError::InvertedTriangle { triangle: 1, .. }),
        "{e}"
    );
    let mut flat = nodes.clone();
    flat[2] = Point3::new(2.0, 0.0, 0.0);
    let e = Mesh::new(flat, vec![[0, 1, 2]], vec![Constraint::Free; 4]).unwrap_err();
    assert!(
        matches!(e, SimError::DegenerateTriangle { triangle: 0, .. }),
        "{e}"
    );
    assert!(Mesh::new(nodes, vec![[0, 1, 2], [1, 3, 2]], c).is_ok());
}

/// The ellipse and the rectangle cover their windows' areas, are
/// clamped on their rims and face +z.
#[test]
fn ellipse_and_rectangle_windows() {
    let area = |m: &Mesh| -> f64 {
        m.triangles
            .iter()
            .map(|t| {
                let p = t.map(|i| m.nodes[i as usize]);
                let z = (p[1] - p[0]).cross(&(p[2] - p[0])).z / 2.0;
                assert!(z > 0.0);
                z
            })
            .sum()
    };
    let e = ellipse(0.04, 0.02, 24).unwrap();
    let want = std::f64::consts::PI * 0.04 * 0.02;
    // the inscribed polygon of 144 sides
    assert!((area(&e) / want - 1.0).abs() < 2e-3, "{}", area(&e));
    for (p, c) in e.nodes.iter().zip(&e.constraints) {
        let on_rim = ((p.x / 0.04).powi(2) + (p.y / 0.02).powi(2) - 1.0).abs() < 1e-9;
        assert_eq!(on_rim, *c == Constraint::Fixed);
    }
    for quarter in [true, false] {
        let r = rectangle(RectangleOptions {
            length_m: 0.16,
            width_m: 0.02,
            half_cells: 5,
            quarter,
        })
        .unwrap();
        let whole = 0.16 * 0.02 / if quarter { 4.0 } else { 1.0 };
        assert!((area(&r) / whole - 1.0).abs() < 1e-12);
        let apex = r.probe("apex").unwrap();
        assert_eq!(r.nodes[apex], Point3::origin());
        let fixed = r
            .constraints
            .iter()
            .filter(|c| **c == Constraint::Fixed)
            .count();
        let (nx, ny) = (40, 5);
        let want = if quarter { nx + ny + 1 } else { 4 * (nx + ny) };
        assert_eq!(fixed, want);
    }
}

#[test]
fn sheet_is_clamped_on_one_edge() {
    let m = sheet(SheetOptions {
        length_m: 1.0,
        width_m: 1.0,
        edge_length_m: 0.1,
    })
    .unwrap();
    let fixed = m
        .constraints
        .iter()
        .filter(|c| **c == Constraint::Fixed)
        .count();
    assert_eq!(fixed, 11);
    let area: f64 = m
        .triangles
        .iter()
        .map(|t| {
            let p = t.map(|i| m.nodes[i as usize]);
            (p[1] - p[0]).cross(&(p[2] - p[0])).z / 2.0
        })
        .sum();
    assert!((area - 1.0).abs() < 1e-12, "{area}");
}
