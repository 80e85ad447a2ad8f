//! The SPD scenes, each ported from its C program: balls ("sphereflake"),
//! tetra, jacks, rings, gears, lattice, shells, mount, tree.

use super::spdlib::*;
use super::{Mat, C3, C4, X_AXIS, Y_AXIS, Z_AXIS};
use std::f64::consts::PI;

/// The light scale the SPD programs compute: 1 for NFF output.
pub(super) const LSCALE_NFF: f64 = 1.0;

// ---------------------------------------------------------------------------
// balls.c — "sphereflake"

pub(super) fn balls(lib: &mut Lib, size: u32) {
    pub(super) fn create_objset() -> [C4; 9] {
        let dist = 1.0 / 2.0f64.sqrt();
        let mut trio_dir: [C4; 3] = [
            [dist, dist, 0.0, 0.0],
            [dist, 0.0, -dist, 0.0],
            [0.0, dist, -dist, 0.0],
        ];
        let mut axis = [1.0, -1.0, 0.0];
        normalize(&mut axis);
        let mx = axis_rotate_matrix(&axis, (2.0 / 6.0f64.sqrt()).asin());
        for t in trio_dir.iter_mut() {
            *t = transform_coord(t, &mx);
        }
        let mut objset = [[0.0; 4]; 9];
        for num_set in 0..3 {
            let mx = rotate_matrix(Z_AXIS, num_set as f64 * 2.0 * PI / 3.0);
            for num_vert in 0..3 {
                objset[num_set * 3 + num_vert] = transform_coord(&trio_dir[num_vert], &mx);
            }
        }
        objset
    }

    pub(super) fn output_object(
        lib: &mut Lib,
        objset: &[C4; 9],
        depth: u32,
        center: C4,
        direction: C4,
    ) {
        lib.sphere(center);
        if depth > 0 {
            let depth = depth - 1;
            let mx = if direction[2] >= 0.9999 {
                identity_matrix()
            } else if direction[2] <= -0.9999 {
                rotate_matrix(Y_AXIS, PI)
            } else {
                let z_axis = [0.0, 0.0, 1.0];
                let mut axis = cross(&z_axis, &direction);
                normalize(&mut axis);
                let angle = dot(&z_axis, &direction).acos();
                axis_rotate_matrix(&axis, angle)
            };
            let scale = center[3] * (1.0 + direction[3]);
            for obj in objset {
                let mut child_pt = transform_coord(obj, &mx);
                child_pt[0] = child_pt[0] * scale + center[0];
                child_pt[1] = child_pt[1] * scale + center[1];
                child_pt[2] = child_pt[2] * scale + center[2];
                child_pt[3] = center[3] * direction[3];
                let mut child_dir = [
                    child_pt[0] - center[0],
                    child_pt[1] - center[1],
                    child_pt[2] - center[2],
                    0.0,
                ];
                child_dir[0] /= scale;
                child_dir[1] /= scale;
                child_dir[2] /= scale;
                child_dir[3] = direction[3];
                output_object(lib, objset, depth, child_pt, child_dir);
            }
        }
    }

    let radius = 1.0;
    lib.background([0.078, 0.361, 0.753]);
    lib.viewpoint(
        [2.1, 1.3, 1.7],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        0.01,
        512,
        512,
    );
    lib.light([4.0, 3.0, 2.0, LSCALE_NFF]);
    lib.light([1.0, -4.0, 4.0, LSCALE_NFF]);
    lib.light([-3.0, 1.0, 5.0, LSCALE_NFF]);
    lib.color([1.0, 0.75, 0.33], 0.2, 0.8, 0.0, 0.0, 0.0, 0.0, 1.0);
    let b = [12.0 * radius, 12.0 * radius, -radius / 2.0];
    let mut backg = [
        [b[0], b[1], b[2]],
        [-b[0], b[1], b[2]],
        [-b[0], -b[1], b[2]],
        [b[0], -b[1], b[2]],
    ];
    lib.polygon(&mut backg);
    lib.color([1.0, 0.9, 0.7], 0.0, 0.5, 0.5, 0.5, 37.0, 0.0, 1.0);
    let objset = create_objset();
    output_object(
        lib,
        &objset,
        size,
        [0.0, 0.0, 0.0, radius / 2.0],
        [0.0, 0.0, 1.0, 1.0 / 3.0],
    );
}

// ---------------------------------------------------------------------------
// tetra.c — recursive tetrahedral pyramid

pub(super) fn tetra(lib: &mut Lib, size: u32) {
    pub(super) fn create_tetra(lib: &mut Lib, depth: u32, center: C4) {
        if depth <= 1 {
            let mut obj_pt = [[0.0; 3]; 4];
            let mut n = 0;
            for x in [-1i32, 1] {
                for y in [-1i32, 1] {
                    for z in [-1i32, 1] {
                        if x * y * z == 1 {
                            obj_pt[n] = [
                                center[0] + x as f64 * center[3],
                                center[1] + y as f64 * center[3],
                                center[2] + z as f64 * center[3],
                            ];
                            n += 1;
                        }
                    }
                }
            }
            for face in 0..4 {
                let mut ord = [face % 4, (face + 1) % 4, (face + 2) % 4];
                if face % 2 == 1 {
                    ord.swap(0, 2);
                }
                let mut pts = [obj_pt[ord[0]], obj_pt[ord[1]], obj_pt[ord[2]]];
                lib.polygon(&mut pts);
            }
        } else {
            for x in [-1i32, 1] {
                for y in [-1i32, 1] {
                    for z in [-1i32, 1] {
                        if x * y * z == 1 {
                            let sub = [
                                center[0] + x as f64 * center[3] / 2.0,
                                center[1] + y as f64 * center[3] / 2.0,
                                center[2] + z as f64 * center[3] / 2.0,
                                center[3] / 2.0,
                            ];
                            create_tetra(lib, depth - 1, sub);
                        }
                    }
                }
            }
        }
    }

    lib.background([0.078, 0.361, 0.753]);
    lib.viewpoint(
        [1.022846, -3.177154, -2.174512],
        [-0.004103, -0.004103, 0.216539],
        [-0.816497, -0.816497, 0.816497],
        45.0,
        1.0,
        1.0,
        512,
        512,
    );
    lib.light([2.0, -18.0, -5.0, LSCALE_NFF]);
    lib.color([1.0, 0.2, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    create_tetra(lib, size, [0.0, 0.0, 0.0, 1.0]);
}

// ---------------------------------------------------------------------------
// jacks.c — recursive jacks (Alexander Enzmann)

pub(super) fn jacks(lib: &mut Lib, size: u32) {
    pub(super) fn make_jack_obj(lib: &mut Lib) {
        lib.tx_push();
        lib.tx_scale([0.75, 0.75, 0.75]);
        lib.cylcone([-1.0, 0.0, 0.0, 0.1], [1.0, 0.0, 0.0, 0.1]);
        lib.cylcone([0.0, -1.0, 0.0, 0.1], [0.0, 1.0, 0.0, 0.1]);
        lib.cylcone([0.0, 0.0, -1.0, 0.1], [0.0, 0.0, 1.0, 0.1]);
        lib.sphere([1.0, 0.0, 0.0, 0.2]);
        lib.sphere([0.0, 1.0, 0.0, 0.2]);
        lib.sphere([0.0, 0.0, 1.0, 0.2]);
        lib.sphere([-1.0, 0.0, 0.0, 0.2]);
        lib.sphere([0.0, -1.0, 0.0, 0.2]);
        lib.sphere([0.0, 0.0, -1.0, 0.2]);
        lib.tx_pop();
    }

    pub(super) fn make_rec_jack(lib: &mut Lib, depth: u32, max_depth: u32) {
        make_jack_obj(lib);
        if depth < max_depth {
            for i in [-0.5, 0.5] {
                for j in [-0.5, 0.5] {
                    for k in [-0.5, 0.5] {
                        lib.tx_push();
                        lib.tx_translate([i, j, k]);
                        lib.tx_scale([0.5, 0.5, 0.5]);
                        make_rec_jack(lib, depth + 1, max_depth);
                        lib.tx_pop();
                    }
                }
            }
        }
    }

    lib.background([0.2, 0.05, 0.2]);
    lib.viewpoint(
        [0.0, 0.0, -8.0],
        [0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        25.0,
        1.0,
        0.001,
        256,
        256,
    );
    lib.light([-10.0, 3.0, -20.0, LSCALE_NFF]);
    lib.tx_push();
    lib.tx_rotate(X_AXIS, -30.0 * PI / 180.0);
    lib.tx_rotate(Y_AXIS, -20.0 * PI / 180.0);
    lib.color([0.737, 0.561, 0.561], 0.1, 0.7, 0.7, 0.4, 20.0, 0.0, 1.0);
    make_rec_jack(lib, 1, size);
    lib.tx_pop();
}

// ---------------------------------------------------------------------------
// rings.c — pentagonal rings on a dodecahedron, in a pyramid

pub(super) fn rings(lib: &mut Lib, size: u32) {
    pub(super) fn create_dodec(minor_radius: f64) -> [C3; 30] {
        let mut vertex = [[0.0; 3]; 30];
        let scale = 1.0 / (1.0 + minor_radius);
        for (n, v) in vertex.iter_mut().take(5).enumerate() {
            v[0] = scale * (n as f64 * 2.0 * PI / 5.0).cos();
            v[1] = scale * (n as f64 * 2.0 * PI / 5.0).sin();
            v[2] = 0.0;
        }
        let x_rotation = 2.0 * ((PI / 3.0).cos() / (PI / 5.0).sin()).acos();
        let x_matrix = rotate_matrix(X_AXIS, x_rotation);
        for num_pentagon in 1..6 {
            let z_rotation = PI * (2.0 * (num_pentagon - 1) as f64 + 1.0) / 5.0;
            let z_matrix = rotate_matrix(Z_AXIS, z_rotation);
            for num_vertex in 0..5 {
                let temp = transform_point(&vertex[num_vertex], &x_matrix);
                vertex[5 * num_pentagon + num_vertex] = transform_point(&temp, &z_matrix);
            }
        }
        vertex
    }

    let radius = 0.07412;
    let spread = 1.0 / (PI / 8.0).sin();
    const SPREAD_OUT: f64 = 1.0;
    let (y_diff, xz_diff) = if SPREAD_OUT <= spread {
        (spread / SPREAD_OUT, 1.0)
    } else {
        (1.0, SPREAD_OUT / spread)
    };
    lib.background([0.078, 0.361, 0.753]);
    let from = [-1.0, -spread, 0.5];
    let at = [from[0], from[1] + 1.0, from[2]];
    lib.viewpoint(from, at, [0.0, 0.0, 1.0], 45.0, 1.0, 1.0, 512, 512);
    lib.light([3.0, -spread, 3.0, LSCALE_NFF]);
    lib.light([-4.0, -spread, 1.0, LSCALE_NFF]);
    lib.light([2.0, -spread, -4.0, LSCALE_NFF]);
    lib.color([1.0, 1.0, 1.0], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let wy = y_diff * (size + 1) as f64;
    let wxz = 1.01 * (wy - from[1]) * (PI / 8.0).tan();
    let mut wall = [
        [wxz + from[0], wy, wxz + from[2]],
        [-wxz + from[0], wy, wxz + from[2]],
        [-wxz + from[0], wy, -wxz + from[2]],
        [wxz + from[0], wy, -wxz + from[2]],
    ];
    lib.polygon(&mut wall);
    let ring_color = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 0.0],
    ];
    let dodec = create_dodec(radius);
    for num_depth in 0..size as i32 {
        let oy = y_diff * (num_depth + 1) as f64;
        for num_objz in 0..=num_depth {
            let oz = xz_diff * (2 * num_objz - num_depth) as f64;
            for num_objx in 0..=num_depth {
                let ox = xz_diff * (2 * num_objx - num_depth) as f64;
                for num_elem in 0..30 {
                    let base = [
                        dodec[num_elem][0] + ox,
                        dodec[num_elem][1] + oy,
                        dodec[num_elem][2] + oz,
                        radius,
                    ];
                    let prev_elem = if num_elem % 5 == 0 {
                        lib.color(ring_color[num_elem / 5], 0.0, 0.5, 0.2, 0.3, 37.0, 0.0, 0.0);
                        num_elem + 4
                    } else {
                        num_elem - 1
                    };
                    let apex = [
                        dodec[prev_elem][0] + ox,
                        dodec[prev_elem][1] + oy,
                        dodec[prev_elem][2] + oz,
                        radius,
                    ];
                    lib.cylcone(base, apex);
                    lib.sphere(base);
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------
// gears.c — meshing gears with concave faces

pub(super) fn gears(lib: &mut Lib, size: u32) {
    const TEETH: usize = 36;
    const OUTER_EDGE_RATIO: f64 = 0.995;
    const INNER_EDGE_RATIO: f64 = 0.9;
    const EDGE_DIFF: f64 = 1.0 - INNER_EDGE_RATIO;
    const DEPTH_RATIO: f64 = 0.1;

    pub(super) fn create_tooth(
        gear_angle: f64,
        tooth_angle: f64,
        center: C3,
        outer: C3,
        inner: C3,
        out: &mut [C3],
    ) {
        let add = |v: C3| [v[0] + center[0], v[1] + center[1], v[2] + center[2]];
        let mx = rotate_matrix(Z_AXIS, gear_angle - 0.19 * tooth_angle);
        out[0] = add(transform_vector(&outer, &mx));
        let mx = rotate_matrix(Z_AXIS, gear_angle + 0.19 * tooth_angle);
        out[1] = add(transform_vector(&outer, &mx));
        let mx = rotate_matrix(Z_AXIS, gear_angle + 0.3 * tooth_angle);
        out[2] = add(transform_vector(&inner, &mx));
        let mx = rotate_matrix(Z_AXIS, gear_angle + 0.7 * tooth_angle);
        out[3] = add(transform_vector(&inner, &mx));
    }

    pub(super) fn create_gear(
        lib: &mut Lib,
        center: C3,
        offset_angle: f64,
        outer_radius: f64,
        inner_radius: f64,
        thickness: f64,
    ) {
        let mut outer = [outer_radius, 0.0, 0.0];
        let mut inner = [inner_radius, 0.0, 0.0];
        let tooth_angle = 2.0 * PI / TEETH as f64;
        let mut pts = vec![[0.0; 3]; 4 * TEETH];
        for t in 0..TEETH {
            let gear_angle = offset_angle + 2.0 * PI * t as f64 / TEETH as f64;
            create_tooth(
                gear_angle,
                tooth_angle,
                center,
                outer,
                inner,
                &mut pts[t * 4..t * 4 + 4],
            );
        }
        lib.polygon(&mut pts);
        for side in 0..4 * TEETH {
            let next = (side + 1) % (4 * TEETH);
            let mut s = [pts[side], pts[side], pts[next], pts[next]];
            s[1][2] -= thickness;
            s[2][2] -= thickness;
            lib.polygon(&mut s);
        }
        outer[2] = -thickness;
        inner[2] = -thickness;
        for t in 0..TEETH {
            let gear_angle = offset_angle - 2.0 * PI * t as f64 / TEETH as f64;
            create_tooth(
                gear_angle,
                -tooth_angle,
                center,
                outer,
                inner,
                &mut pts[t * 4..t * 4 + 4],
            );
        }
        lib.polygon(&mut pts);
    }

    /// def.h's FRACTION: the part after the decimal point (C int cast).
    pub(super) fn fraction(a: f64) -> f64 {
        a - (a as i32) as f64
    }

    lib.background([0.078, 0.361, 0.753]);
    lib.viewpoint(
        [-1.1, -2.1, 2.6],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        1.0,
        512,
        512,
    );
    lib.light([2.0, 4.0, 4.0, LSCALE_NFF]);
    lib.light([-2.0, 4.0, 3.0, LSCALE_NFF]);
    lib.light([2.0, -2.5, 2.5, LSCALE_NFF]);
    lib.light([-1.0, -4.0, 2.0, LSCALE_NFF]);
    lib.light([-1.111, -2.121, 2.626, LSCALE_NFF]);
    lib.color([1.0, 0.85, 0.7], 0.0, 0.3, 0.6, 0.3, 37.0, 0.0, 0.0);
    let mut ground = [
        [2.0, 2.0, 0.0],
        [-2.0, 2.0, 0.0],
        [-2.0, -2.0, 0.0],
        [2.0, -2.0, 0.0],
    ];
    lib.polygon(&mut ground);
    let sf = size as f64;
    let outer_radius = 1.0 / (sf - (size - 1) as f64 * EDGE_DIFF / 2.0);
    let zero = [-1.0 + outer_radius, -1.0 + outer_radius, 1.0];
    let offset = [
        outer_radius * (2.0 - EDGE_DIFF),
        outer_radius * (2.0 - EDGE_DIFF),
        -1.0 / sf,
    ];
    let size = size as i32;
    for iz in 0..size {
        let cz = zero[2] + iz as f64 * offset[2];
        for iy in 0..size {
            let cy = zero[1] + iy as f64 * offset[1];
            for ix in 0..size {
                let cx = zero[0] + ix as f64 * offset[0];
                let mut c = [
                    0.01 + fraction((ix * 3 + iy * 2 + iz + 1) as f64 * 5.0 / 7.0),
                    0.01 + fraction((iy * 3 + iz * 2 + ix + 1) as f64 * 3.0 / 7.0),
                    0.01 + fraction((iz * 3 + ix * 2 + iy + 1) as f64 * 2.0 / 7.0),
                ];
                let mut cs = if c[0] > c[1] { c[0] } else { c[1] };
                cs = if cs > c[2] { cs } else { c[2] };
                c[0] /= cs;
                c[1] /= cs;
                c[2] /= cs;
                if (ix * 4 + iy * 2 + iz) % 5 == 0 {
                    lib.color(c, 0.0, 0.2, 0.0, 0.0, 0.0, 0.8, 1.1);
                } else {
                    lib.color(c, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
                }
                let angle = PI * ((ix + iy + iz) % 2) as f64 / TEETH as f64;
                let thickness = DEPTH_RATIO.min(1.0 / (2.0 * sf));
                create_gear(
                    lib,
                    [cx, cy, cz],
                    angle,
                    OUTER_EDGE_RATIO * outer_radius,
                    (1.0 - EDGE_DIFF) * outer_radius,
                    thickness,
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------
// lattice.c — spheres joined by cylinders in a cubic lattice (Antonio Costa)

pub(super) fn lattice(lib: &mut Lib, size: u32) {
    const RADIUS1: f64 = 1.0 / 4.0;
    const RADIUS2: f64 = 1.0 / 16.0;
    let sf = size as f64;
    let inv_factor = 1.0 / sf;
    let radius1 = RADIUS1 / sf;
    let radius2 = RADIUS2 / sf;
    let delta = (radius1 * (1.0 - (RADIUS2 / RADIUS1).sqrt())) * 0.99;
    lib.background([0.078, 0.361, 0.753]);
    let half = (size >> 1) as f64;
    let from = [
        (half + 0.5) * inv_factor,
        1.0,
        1.0 - 1.0 / (size << 1) as f64,
    ];
    let at = [
        (half + 0.5) * inv_factor,
        -1.0,
        -1.0 - 1.0 / (size << 1) as f64,
    ];
    lib.viewpoint(from, at, [0.2, 1.0, 0.0], 60.0, 1.0, 0.0, 512, 512);
    let lscale = 1.0 / 6.0f64.sqrt();
    lib.light([2.0, 0.5, 0.5, lscale]);
    lib.light([-1.0, 0.5, 0.5, lscale]);
    lib.light([0.5, 2.0, 0.5, lscale]);
    lib.light([0.5, -1.0, 0.5, lscale]);
    lib.light([0.5, 0.5, 2.0, lscale]);
    lib.light([0.5, 0.5, -1.0, lscale]);
    for x in 0..=size {
        let x0 = x as f64 / sf;
        for y in 0..=size {
            let y0 = y as f64 / sf;
            for z in 0..=size {
                let z0 = z as f64 / sf;
                lib.color([0.9, 0.9, 0.9], 0.0, 0.5, 0.5, 0.5, 37.0, 0.0, 0.0);
                lib.sphere([x0, y0, z0, radius1]);
                if x != size {
                    lib.color([0.9, 0.1, 0.1], 0.1, 0.99, 0.0, 0.0, 0.0, 0.0, 0.0);
                    lib.cylcone(
                        [x0 + delta, y0, z0, radius2],
                        [x0 + inv_factor - delta, y0, z0, radius2],
                    );
                }
                if y != size {
                    lib.color([0.1, 0.9, 0.1], 0.1, 0.99, 0.0, 0.0, 0.0, 0.0, 0.0);
                    lib.cylcone(
                        [x0, y0 + delta, z0, radius2],
                        [x0, y0 + inv_factor - delta, z0, radius2],
                    );
                }
                if z != size {
                    lib.color([0.1, 0.1, 0.9], 0.1, 0.99, 0.0, 0.0, 0.0, 0.0, 0.0);
                    lib.cylcone(
                        [x0, y0, z0 + delta, radius2],
                        [x0, y0, z0 + inv_factor - delta, radius2],
                    );
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------
// shells.c — Pickover's sea shell of spheres

pub(super) fn shells(lib: &mut Lib, size: u32) {
    let fgamma = 1.0;
    let alpha = 0.0;
    let beta = -2.0;
    let a = 0.15;
    let k = 1.0;
    lib.background([0.078, 0.361, 0.753]);
    lib.viewpoint(
        [-6.0, -60.0, 35.0],
        [0.0, 8.0, -15.0],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        0.5,
        512,
        512,
    );
    lib.light([-100.0, -100.0, 100.0, 1.0]);
    lib.color([1.0, 0.8, 0.4], 0.0, 0.8, 0.2, 0.5, 10.0, 0.0, 1.0);
    let steps = (180.0 * 2.0f64.powf(size as f64)) as i64;
    for i in (-steps * 2 / 3)..=(steps / 3) {
        let angle = 3.0 * 6.0 * PI * i as f64 / steps as f64;
        let r = k * (a * angle).exp();
        let z = if alpha > 0.0 { alpha * angle } else { beta * r };
        lib.sphere([r * angle.sin(), r * angle.cos(), z, r / fgamma]);
    }
}

// ---------------------------------------------------------------------------
// mount.c — Carpenter's fractal mountain and four glass spheres

pub(super) fn mount(lib: &mut Lib, size: u32) {
    const FRACTAL_DIMENSION: f64 = 2.2;
    const MOUNTAIN_NO: i64 = 21;
    const X_CORNER: f64 = -1.0;
    const Y_CORNER: f64 = -1.0;
    const WIDTH: f64 = 2.0;

    /// The original (repeating) hash, kept as the SPD does for comparable
    /// images.
    pub(super) fn hash_rand(a: i64, b: i64, c: u32) -> i64 {
        let (a, b) = (a as u64, b as u64);
        (((a << (23 - c)) + (b << (15 - c)) + (a << (7 - c))) & 0xffff) as i64
    }

    pub(super) fn create_spheres(lib: &mut Lib, center: C4) {
        let mut axis = [1.0, 1.0, 0.0];
        normalize(&mut axis);
        let angle = (-1.0f64 / 3.0).acos();
        let pt = [0.0, 0.0, center[3] * (3.0f64 / 2.0).sqrt()];
        lib.sphere([
            center[0] + pt[0],
            center[1] + pt[1],
            center[2] + pt[2],
            center[3],
        ]);
        let mx = axis_rotate_matrix(&axis, angle);
        let new_pt = transform_vector(&pt, &mx);
        for i in 0..3 {
            let mx = rotate_matrix(Z_AXIS, i as f64 * 2.0 * PI / 3.0);
            let s = transform_vector(&new_pt, &mx);
            lib.sphere([
                s[0] + center[0],
                s[1] + center[1],
                s[2] + center[2],
                center[3],
            ]);
        }
    }

    struct M {
        size: u32,
        roughness: f64,
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn grow_mountain(
        lib: &mut Lib,
        m: &M,
        fnum_pts: f64,
        width: i64,
        ll_x: i64,
        ll_y: i64,
        ll_fz: f64,
        lr_fz: f64,
        ur_fz: f64,
        ul_fz: f64,
    ) {
        if width == 1 {
            let l_fx = X_CORNER + ll_x as f64 * WIDTH / fnum_pts;
            let r_fx = X_CORNER + (ll_x + 1) as f64 * WIDTH / fnum_pts;
            let l_fy = Y_CORNER + ll_y as f64 * WIDTH / fnum_pts;
            let u_fy = Y_CORNER + (ll_y + 1) as f64 * WIDTH / fnum_pts;
            for num_tri in 0..2 {
                let mut tri = [[0.0; 3]; 3];
                for (num_vert, v) in tri.iter_mut().enumerate() {
                    *v = match (num_vert + num_tri * 2) % 4 {
                        0 => [l_fx, l_fy, ll_fz],
                        1 => [r_fx, l_fy, lr_fz],
                        2 => [r_fx, u_fy, ur_fz],
                        _ => [l_fx, u_fy, ul_fz],
                    };
                }
                lib.polygon(&mut tri);
            }
        } else {
            let half = width >> 1;
            let hside_length = half as f64 * WIDTH / fnum_pts;
            let rise_height = hside_length * m.roughness;
            let sf = m.size;
            let iz = MOUNTAIN_NO + hash_rand(ll_x + half, ll_y, sf);
            let lower_fz = (ll_fz + lr_fz) / 2.0 + rise_height * gauss_rand(iz);
            let iz = MOUNTAIN_NO + hash_rand(ll_x + width, ll_y + half, sf);
            let right_fz = (lr_fz + ur_fz) / 2.0 + rise_height * gauss_rand(iz);
            let iz = MOUNTAIN_NO + hash_rand(ll_x + half, ll_y + width, sf);
            let upper_fz = (ur_fz + ul_fz) / 2.0 + rise_height * gauss_rand(iz);
            let iz = MOUNTAIN_NO + hash_rand(ll_x, ll_y + half, sf);
            let left_fz = (ul_fz + ll_fz) / 2.0 + rise_height * gauss_rand(iz);
            let iz = MOUNTAIN_NO + hash_rand(ll_x + half, ll_y + half, sf);
            // mount.c's literal 1.4142136, not sqrt(2) to the last bit.
            #[allow(clippy::approx_constant)]
            const ROOT2: f64 = 1.4142136;
            let middle_fz =
                (ll_fz + lr_fz + ur_fz + ul_fz) / 4.0 + ROOT2 * rise_height * gauss_rand(iz);
            grow_mountain(
                lib, m, fnum_pts, half, ll_x, ll_y, ll_fz, lower_fz, middle_fz, left_fz,
            );
            grow_mountain(
                lib,
                m,
                fnum_pts,
                half,
                ll_x + half,
                ll_y,
                lower_fz,
                lr_fz,
                right_fz,
                middle_fz,
            );
            grow_mountain(
                lib,
                m,
                fnum_pts,
                half,
                ll_x + half,
                ll_y + half,
                middle_fz,
                right_fz,
                ur_fz,
                upper_fz,
            );
            grow_mountain(
                lib,
                m,
                fnum_pts,
                half,
                ll_x,
                ll_y + half,
                left_fz,
                middle_fz,
                upper_fz,
                ul_fz,
            );
        }
    }

    lib.background([0.078, 0.361, 0.753]);
    lib.viewpoint(
        [-1.6, 1.6, 1.7],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        0.01,
        512,
        512,
    );
    lib.light([-100.0, -100.0, 100.0, LSCALE_NFF]);
    lib.color([1.0, 1.0, 1.0], 0.0, 0.1, 0.1, 0.4, 6.7, 0.9, 1.5);
    create_spheres(lib, [-0.8, 0.8, 1.00, 0.17]);
    lib.color([0.5, 0.45, 0.35], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let num_pts: i64 = 1 << size;
    let ratio = 2.0 / (2.0f64.ln() / (FRACTAL_DIMENSION - 1.0)).exp();
    let m = M {
        size,
        roughness: (ratio * ratio - 1.0).sqrt(),
    };
    grow_mountain(lib, &m, num_pts as f64, num_pts, 0, 0, 0.0, 0.0, 0.0, 0.0);
}

// ---------------------------------------------------------------------------
// tree.c — Aono & Kunii's tree of cones and spheres

pub(super) fn tree(lib: &mut Lib, size: u32) {
    const BR_ANGLE_0: f64 = 40.0;
    const BR_ANGLE_1: f64 = 25.0;
    const BR_CONTR_0: f64 = 0.65;
    const BR_CONTR_1: f64 = 0.70;
    const BR_DIAMETER: f64 = 0.67;
    const DIV_ANGLE: f64 = 140.0;
    const WIDTH_HEIGHTH_RATIO: f64 = 0.15;

    pub(super) fn grow_tree(lib: &mut Lib, rst: &[Mat; 2], cur: &Mat, scale: f64, depth: u32) {
        let b = transform_point(&[0.0, 0.0, 0.0], cur);
        let base = [b[0], b[1], b[2], scale * WIDTH_HEIGHTH_RATIO];
        let a = transform_point(&[0.0, 0.0, 1.0], cur);
        let apex = [a[0], a[1], a[2], base[3] * BR_DIAMETER];
        lib.cylcone(base, apex);
        lib.sphere(apex);
        if depth > 0 {
            for r in rst {
                let new_mx = matrix_multiply(r, cur);
                grow_tree(lib, rst, &new_mx, scale * BR_DIAMETER, depth - 1);
            }
        }
    }

    lib.background([0.078, 0.361, 0.753]);
    lib.viewpoint(
        [4.5, 0.4, 2.0],
        [0.0, 0.0, 1.5],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        1.0,
        512,
        512,
    );
    for l in [
        [-5.0, 5.0, 50.0],
        [30.0, -30.0, 30.0],
        [-40.0, -30.0, 20.0],
        [10.0, 30.0, 40.0],
        [-30.0, 40.0, 10.0],
        [50.0, 25.0, 20.0],
        [-10.0, -60.0, 30.0],
    ] {
        lib.light([l[0], l[1], l[2], LSCALE_NFF]);
    }
    lib.color([0.2, 0.7, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut field = [
        [50.0, 50.0, 0.0],
        [-50.0, 50.0, 0.0],
        [-50.0, -50.0, 0.0],
        [50.0, -50.0, 0.0],
    ];
    lib.polygon(&mut field);
    lib.color([0.55, 0.4, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut rst = [zero_matrix(); 2];
    for (i, r) in rst.iter_mut().enumerate() {
        let (branch_angle, divergence, contraction) = if i == 0 {
            (BR_ANGLE_0, 90.0, BR_CONTR_0)
        } else {
            (BR_ANGLE_1, DIV_ANGLE + 90.0, BR_CONTR_1)
        };
        let t1 = rotate_matrix(X_AXIS, branch_angle * PI / 180.0);
        let t2 = rotate_matrix(Z_AXIS, divergence * PI / 180.0);
        let tr = matrix_multiply(&t1, &t2);
        let mut st = identity_matrix();
        st[0][0] = contraction;
        st[1][1] = contraction;
        st[2][2] = contraction;
        st[3][2] = 1.0;
        *r = matrix_multiply(&tr, &st);
    }
    grow_tree(lib, &rst, &identity_matrix(), 1.0, size);
}
