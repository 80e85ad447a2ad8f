//! The reference intersections against hand-worked hits: each shape's
//! visible side, its inside, caps, and the planar shapes' edges.

use super::*;

fn intersect(s: &Shape, r: &Ray, tmin: f64, tmax: f64, two_sided: bool) -> Option<SurfaceHit> {
    s.intersect(r, tmin, tmax, two_sided)
}

fn ray(o: [f64; 3], d: [f64; 3]) -> Ray {
    Ray {
        o: o.into(),
        d: Vec3::from(d).normalized(),
    }
}
const INF: f64 = f64::INFINITY;

#[test]
fn sphere_front_back_and_inside() {
    let s = Shape::from(Sphere {
        center: Vec3::new(0.0, 0.0, 5.0),
        radius: 2.0,
        inside: false,
    });
    let h = intersect(&s, &ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), 0.0, INF, false).unwrap();
    assert_eq!(h.t, 3.0);
    assert_eq!(h.n, Vec3::new(0.0, 0.0, -1.0));
    // From inside, one-sided: the exit is the back side, not seen.
    assert!(intersect(&s, &ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]), 0.0, INF, false).is_none());
    let h = intersect(&s, &ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]), 0.0, INF, true).unwrap();
    assert_eq!((h.t, h.front), (2.0, false));
    // Negative NFF radius: only the inside is visible.
    let s = Shape::from(Sphere {
        center: Vec3::new(0.0, 0.0, 5.0),
        radius: 2.0,
        inside: true,
    });
    let h = intersect(&s, &ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), 0.0, INF, false).unwrap();
    assert_eq!((h.t, h.n), (7.0, Vec3::new(0.0, 0.0, -1.0)));
    // Grazing at x = 1.2: t = 5 - sqrt(4 - 1.44) = 3.4.
    let h = intersect(
        &Shape::from(Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 2.0,
            inside: false,
        }),
        &ray([1.2, 0.0, 0.0], [0.0, 0.0, 1.0]),
        0.0,
        INF,
        false,
    )
    .unwrap();
    assert!((h.t - 3.4).abs() < 1e-12);
}

#[test]
fn cylinder_cone_and_caps() {
    // Cylinder along z from 0 to 2, radius 1; ray along -x at z = 1.
    let c = Shape::from(Cone {
        base: Vec3::ZERO,
        base_radius: 1.0,
        apex: Vec3::new(0.0, 0.0, 2.0),
        apex_radius: 1.0,
        inside: false,
        caps: false,
    });
    let h = intersect(&c, &ray([5.0, 0.0, 1.0], [-1.0, 0.0, 0.0]), 0.0, INF, false).unwrap();
    assert!((h.t - 4.0).abs() < 1e-12 && (h.n - Vec3::new(1.0, 0.0, 0.0)).length() < 1e-12);
    // Above the top: missed (open).
    assert!(intersect(&c, &ray([5.0, 0.0, 2.5], [-1.0, 0.0, 0.0]), 0.0, INF, false).is_none());
    // Down the axis: open, the inside wall is a back side.
    assert!(intersect(&c, &ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0]), 0.0, INF, false).is_none());
    let capped = Shape::from(Cone {
        base: Vec3::ZERO,
        base_radius: 1.0,
        apex: Vec3::new(0.0, 0.0, 2.0),
        apex_radius: 1.0,
        inside: false,
        caps: true,
    });
    let h = intersect(
        &capped,
        &ray([0.5, 0.0, 5.0], [0.0, 0.0, -1.0]),
        0.0,
        INF,
        false,
    )
    .unwrap();
    assert_eq!((h.t, h.n), (3.0, Vec3::new(0.0, 0.0, 1.0)));
    // Cone radius 1 at z=0 to 0.5 at z=2: at z=1 radius is 0.75; the
    // outward normal leans up by atan(0.25).
    let k = Shape::from(Cone {
        base: Vec3::ZERO,
        base_radius: 1.0,
        apex: Vec3::new(0.0, 0.0, 2.0),
        apex_radius: 0.5,
        inside: false,
        caps: false,
    });
    let h = intersect(&k, &ray([5.0, 0.0, 1.0], [-1.0, 0.0, 0.0]), 0.0, INF, false).unwrap();
    assert!((h.t - 4.25).abs() < 1e-12, "{}", h.t);
    let e = Vec3::new(1.0, 0.0, 0.25).normalized();
    assert!((h.n - e).length() < 1e-12, "{:?}", h.n);
}

#[test]
fn box_rectangle_triangle_polygon() {
    let b = Shape::from(AaBox {
        min: Vec3::new(-1.0, -1.0, -1.0),
        max: Vec3::new(1.0, 2.0, 3.0),
    });
    let h = intersect(
        &b,
        &ray([0.0, 10.0, 0.0], [0.0, -1.0, 0.0]),
        0.0,
        INF,
        false,
    )
    .unwrap();
    assert_eq!((h.t, h.n), (8.0, Vec3::new(0.0, 1.0, 0.0)));
    assert!(intersect(&b, &ray([0.0, 0.0, 0.0], [0.0, -1.0, 0.0]), 0.0, INF, false).is_none());
    let r = Shape::from(Rectangle {
        corner: Vec3::ZERO,
        edge1: Vec3::new(2.0, 0.0, 0.0),
        edge2: Vec3::new(0.0, 1.0, 0.0),
    });
    assert_eq!(
        intersect(&r, &ray([1.9, 0.9, 4.0], [0.0, 0.0, -1.0]), 0.0, INF, false)
            .unwrap()
            .t,
        4.0
    );
    assert!(intersect(&r, &ray([2.1, 0.5, 4.0], [0.0, 0.0, -1.0]), 0.0, INF, false).is_none());
    assert!(
        intersect(&r, &ray([1.0, 0.5, -4.0], [0.0, 0.0, 1.0]), 0.0, INF, false).is_none(),
        "back side"
    );
    let tri = Shape::from(Triangle {
        v: [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ],
        normals: None,
    });
    assert_eq!(
        intersect(
            &tri,
            &ray([0.2, 0.2, 1.0], [0.0, 0.0, -1.0]),
            0.0,
            INF,
            false
        )
        .unwrap()
        .t,
        1.0
    );
    assert!(intersect(
        &tri,
        &ray([0.6, 0.6, 1.0], [0.0, 0.0, -1.0]),
        0.0,
        INF,
        false
    )
    .is_none());
    assert!(intersect(
        &tri,
        &ray([0.2, 0.2, -1.0], [0.0, 0.0, 1.0]),
        0.0,
        INF,
        false
    )
    .is_none());
    // Concave arrow: (0,0) (2,0) (2,2) (1,1) (0,2); the notch at (1,1.5)
    // is outside, (1,0.5) and (1.8,1.5) inside.
    let v = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [1.0, 1.0], [0.0, 2.0]]
        .map(|[x, y]| Vec3::new(x, y, 0.0))
        .to_vec();
    let p = Shape::from(Polygon { v, normals: None });
    let hit = |x: f64, y: f64| {
        intersect(&p, &ray([x, y, 1.0], [0.0, 0.0, -1.0]), 0.0, INF, false).is_some()
    };
    assert!(hit(1.0, 0.5) && hit(1.8, 1.5) && !hit(1.0, 1.5) && !hit(2.5, 0.5));
}

#[test]
fn disc_front_back_rim_and_bounds() {
    // The disc of radius 2 about (1, 0, 3) in the plane x + z = 4, its
    // visible side towards +x +z.
    let d = Shape::from(Disc {
        center: Vec3::new(1.0, 0.0, 3.0),
        normal: Vec3::new(3.0, 0.0, 3.0),
        radius: 2.0,
    });
    // Straight down from (1, 1.5, 13): the plane at z = 3, 1.5 from the
    // centre, inside.
    let h = intersect(
        &d,
        &ray([1.0, 1.5, 13.0], [0.0, 0.0, -1.0]),
        0.0,
        INF,
        false,
    )
    .unwrap();
    assert!((h.t - 10.0).abs() < 1e-12, "{}", h.t);
    let e = Vec3::new(1.0, 0.0, 1.0).normalized();
    assert!((h.n - e).length() < 1e-12 && h.front, "{h:?}");
    // 2.5 from the centre: off the rim.
    assert!(intersect(
        &d,
        &ray([1.0, 2.5, 13.0], [0.0, 0.0, -1.0]),
        0.0,
        INF,
        false
    )
    .is_none());
    // From below: the back, seen only two-sided, its normal still the
    // visible side's.
    let up = ray([1.0, 0.5, -7.0], [0.0, 0.0, 1.0]);
    assert!(intersect(&d, &up, 0.0, INF, false).is_none(), "back side");
    let h = intersect(&d, &up, 0.0, INF, true).unwrap();
    assert!((h.t - 10.0).abs() < 1e-12 && !h.front, "{h:?}");
    // Parallel to the plane: no hit.
    assert!(intersect(&d, &ray([0.0, 0.0, 4.0], [1.0, 0.0, -1.0]), 0.0, INF, true).is_none());
    // Its bounds: the rim reaches 2 sin 45 deg along x and z, 2 along y.
    let b = d.bounds();
    let s = 2.0f64.sqrt();
    for (got, want) in [
        (b.min, Vec3::new(1.0 - s, -2.0, 3.0 - s)),
        (b.max, Vec3::new(1.0 + s, 2.0, 3.0 + s)),
    ] {
        assert!((got - want).length() < 1e-12, "{got:?} {want:?}");
    }
    // A cell beside the disc's plane is not met, one it crosses is.
    let far = Aabb {
        min: Vec3::new(2.0, -1.0, 3.5),
        max: Vec3::new(3.0, 1.0, 4.4),
    };
    let near = Aabb {
        min: Vec3::new(0.5, -1.0, 3.0),
        max: Vec3::new(1.5, 1.0, 3.5),
    };
    assert!(!d.may_overlap(&far) && d.may_overlap(&near));
    // Degenerate: no radius, no normal.
    let mut bad = Disc {
        center: Vec3::ZERO,
        normal: Vec3::ZERO,
        radius: 1.0,
    };
    assert!(Shape::from(bad.clone())
        .degeneracy()
        .unwrap()
        .contains("normal"));
    bad.normal = Vec3::new(0.0, 0.0, 1.0);
    bad.radius = -1.0;
    assert!(Shape::from(bad).degeneracy().unwrap().contains("radius"));
}
