//! rings.c: pentagonal rings on a dodecahedron, in a pyramid.

use std::f64::consts::PI;

use super::super::spdlib::*;
use super::super::{C3, X_AXIS, Z_AXIS};
use super::LSCALE_NFF;

pub(crate) fn rings(lib: &mut Lib, size: u32) {
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
