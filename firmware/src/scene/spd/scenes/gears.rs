//! gears.c: meshing gears with concave faces.

use std::f64::consts::PI;

use super::super::spdlib::*;
use super::super::{C3, Z_AXIS};
use super::LSCALE_NFF;

const TEETH: usize = 36;
const OUTER_EDGE_RATIO: f64 = 0.995;
const INNER_EDGE_RATIO: f64 = 0.9;
const EDGE_DIFF: f64 = 1.0 - INNER_EDGE_RATIO;
const DEPTH_RATIO: f64 = 0.1;

fn create_tooth(
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

fn create_gear(
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
fn fraction(a: f64) -> f64 {
    a - (a as i32) as f64
}

/// gears.c's `main`: the view, the lights, the floor and `4^size` gears.
pub(crate) fn gears(lib: &mut Lib, size: u32) {
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
