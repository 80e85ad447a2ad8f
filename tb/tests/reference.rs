//! The reference renderer against hand-computed pixels and ray counts, and
//! its images bit-identical whatever the number of threads.

use firmware::scene::{native, Scene};
use tb::reference::{render, Options, NO_HIT};

fn scene(body: &str) -> Scene {
    let head = "background = [0.2, 0.3, 0.4]\n[camera]\nfrom = [0, 0, 10]\nat = [0, 0, 0]\nup = [0, 1, 0]\nangle = 45\n\
                [[light]]\nposition = [0, 0, 10]\ncolor = [1, 1, 1]\n";
    native::parse(&format!("{head}{body}"), "t.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn opts(w: u32, h: u32, depth: u32) -> Options {
    Options {
        width: w,
        height: h,
        max_depth: depth,
        corners: false,
        progress: false,
    }
}

#[test]
fn lit_sphere_centre_pixel_by_hand() {
    // The centre ray hits (0, 0, 1) head on, light behind the eye: N.L = 1,
    // R.V = 1. Colour = Kd*colour + Ks*1^shine + Ks*background
    //                 = 0.8*(1, 0.5, 0.25) + 0.1 + 0.1*(0.2, 0.3, 0.4).
    let s = scene(
        "[material.m]\ncolor = [1, 0.5, 0.25]\nkd = 0.8\nks = 0.1\nshine = 5\n\
         [[object]]\ntype = \"sphere\"\nmaterial = \"m\"\ncenter = [0, 0, 0]\nradius = 1\n",
    );
    let img = render(&s, &opts(3, 3, 5));
    let c = img.rgb[4];
    for (got, want) in [(c.x, 0.92), (c.y, 0.53), (c.z, 0.34)] {
        assert!((got - want).abs() < 1e-12, "{c:?}");
    }
    // The corner rays pass 30 degrees off axis, missing the sphere (which
    // subtends 5.7 degrees): background.
    assert_eq!(img.rgb[0], s.background);
    assert_eq!(
        img.hits,
        vec![NO_HIT, NO_HIT, NO_HIT, NO_HIT, 0, NO_HIT, NO_HIT, NO_HIT, NO_HIT]
    );
    // 1 eye hit: 1 shadow ray (facing the light), 1 reflection ray (Ks > 0).
    let st = img.stats;
    assert_eq!(
        (
            st.eye_hit_rays,
            st.shadow_rays,
            st.reflect_rays,
            st.refract_rays
        ),
        (1, 1, 1, 0)
    );
    // Depth 1: no reflection ray, and the reflected term is gone.
    let img = render(&s, &opts(3, 3, 1));
    assert!((img.rgb[4].x - 0.9).abs() < 1e-12);
    assert_eq!(img.stats.reflect_rays, 0);
}

#[test]
fn glass_sphere_ray_counts_by_hand() {
    // One eye ray down the axis of a transmitting sphere, depth 3.
    // Depth 1, front (outside): shadow ray (light behind the eye),
    //   reflection and refraction rays (depth 2).
    // Depth 2 refracted, back side from inside (two-sided): its normal
    //   flipped towards the eye faces the light: shadow ray; reflection and
    //   refraction rays (depth 3). The depth-2 reflection leaves the sphere.
    // Depth 3 reflected (inside) hits the front from inside: normal faces
    //   away from the light, no shadow ray; depth 3 spawns nothing.
    let s = scene(
        "[material.glass]\ncolor = [1, 1, 1]\nkd = 0.1\nks = 0.1\nshine = 5\nt = 0.8\nior = 1.5\n\
         [[object]]\ntype = \"sphere\"\nmaterial = \"glass\"\ncenter = [0, 0, 0]\nradius = 1\n",
    );
    let st = render(&s, &opts(1, 1, 3)).stats;
    assert_eq!(
        (
            st.eye_hit_rays,
            st.shadow_rays,
            st.reflect_rays,
            st.refract_rays
        ),
        (1, 2, 2, 2)
    );
}

#[test]
fn images_do_not_depend_on_thread_count() {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/default.toml");
    let s = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| render(&s, &opts(64, 48, 5)))
    };
    let (a, b) = (run(1), run(3));
    let bits = |i: &tb::reference::Image| {
        i.rgb
            .iter()
            .flat_map(|c| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()])
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.hits, b.hits);
    assert_eq!(a.stats, b.stats);
    // All five of the paper's primitive types are in the default scene and
    // in view.
    let mut seen: Vec<&str> = a
        .hits
        .iter()
        .filter(|&&h| h != NO_HIT)
        .map(|&h| s.objects[h as usize].shape.prim_type().name())
        .collect();
    seen.sort();
    seen.dedup();
    assert_eq!(seen, ["box", "cylinder", "rectangle", "sphere", "triangle"]);
}

#[test]
fn bvh_agrees_with_brute_force() {
    use firmware::scene::Vec3;
    use tb::reference::shapes::{intersect, Ray};
    use tb::reference::Tracer;
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    for path in [
        dir.join("../scenes/default.toml"),
        dir.join("../scenes/spd/jacks-1.nff"),
        dir.join("../scenes/spd/tetra-6.nff"),
    ] {
        let s = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let tracer = Tracer::new(&s);
        let b = s.bounds();
        // A fixed linear congruential sequence: rays from points around the
        // scene's box in every direction.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut hits = 0;
        for _ in 0..3000 {
            let e = b.extent() * 1.5;
            let o = b.center()
                + Vec3::new(
                    (rnd() - 0.5) * e.x,
                    (rnd() - 0.5) * e.y,
                    (rnd() - 0.5) * e.z,
                );
            let d = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
            if d.length() < 1e-3 {
                continue;
            }
            let r = Ray {
                o,
                d: d.normalized(),
            };
            let mut brute: Option<(usize, f64)> = None;
            for (i, obj) in s.objects.iter().enumerate() {
                let two = s.materials[obj.material].t > 0.0;
                if let Some(h) = intersect(&obj.shape, &r, 0.0, f64::INFINITY, two) {
                    if brute.is_none_or(|(_, t)| h.t < t) {
                        brute = Some((i, h.t));
                    }
                }
            }
            let fast = tracer.closest(&r).map(|(i, h)| (i, h.t));
            assert_eq!(fast, brute, "{}: ray {r:?}", path.display());
            hits += brute.is_some() as u32;
        }
        assert!(
            hits > 100,
            "{}: only {hits} of the rays hit",
            path.display()
        );
    }
}
