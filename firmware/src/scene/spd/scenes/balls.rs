//! balls.c: "sphereflake".

use std::f64::consts::PI;

use super::super::spdlib::*;
use super::super::{C4, Y_AXIS, Z_AXIS};
use super::LSCALE_NFF;

pub(crate) fn balls(lib: &mut Lib, size: u32) {
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
