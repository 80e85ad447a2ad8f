//! The primitives' records, kernels and table held against each other.

use super::*;
use record::{Layout, W};

/// Every chip type finds its primitive in the table, under its own
/// name, once; the glass type's name is the opaque one's with `glass_`.
#[test]
fn every_type_has_its_primitive_in_the_table() {
    for t in ChipType::ALL {
        let p = t.primitive();
        let n = PRIMITIVES.iter().filter(|q| q.names() == p.names()).count();
        assert_eq!(n, 1, "{t:?}");
        assert_eq!(t.name(), p.names()[t.refracts() as usize]);
        assert_eq!(p.names()[1], format!("glass_{}", p.names()[0]));
    }
    let mut names: Vec<&str> = ChipType::ALL.iter().map(|t| t.name()).collect();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), ChipType::ALL.len());
    assert_eq!(ChipType::ALL.len(), 2 * PRIMITIVES.len());
}

/// Every kernel reads exactly the words its record (or its part of the
/// record) holds, in every variant: a kernel reading one word less or
/// more than the writer wrote would stream the next record's words.
#[test]
fn every_kernel_reads_exactly_its_record() {
    for fine_normals in [false, true] {
        for sphere_fine in [false, true] {
            for dp in [Datapath::W16, Datapath::W32] {
                let g = Gen {
                    datapath: dp,
                    approx: Approx::default(),
                    fine_normals,
                    test_cuts: fine_normals,
                    published: !fine_normals,
                };
                let fit = Fit {
                    sphere_fine,
                    fine_normals,
                    cyl_bound: fine_normals,
                    ..Fit::default()
                };
                for s in [Sides::Front, Sides::Both] {
                    assert_eq!(sphere::kernel(&g, &fit, s).fb_reads, sphere::words(&fit));
                    assert_eq!(aabox::kernel(&g, s).fb_reads, aabox::words(s));
                    for i in [
                        planar::Inside::Triangle,
                        planar::Inside::Rectangle,
                        planar::Inside::Disc,
                    ] {
                        assert_eq!(planar::kernel(&g, i, s).fb_reads, planar::WORDS);
                    }
                    for p in [&planar::RECTANGLE, &planar::TRIANGLE, &planar::DISC] {
                        for (name, k) in p.kernels(s, &g, &fit) {
                            assert_eq!(k.fb_reads, p.record_words(s, &fit, 0, false), "{name}");
                        }
                    }
                    assert_eq!(
                        smooth_triangle::kernel(&g, s).fb_reads,
                        smooth_triangle::WORDS
                    );
                    let p: Vec<usize> = polygon::kernels(&g, s, polygon::Form::Plain)
                        .iter()
                        .map(|(_, k)| k.fb_reads)
                        .collect();
                    assert_eq!(
                        p,
                        [
                            polygon::HEAD_WORDS,
                            polygon::EDGE_WORDS,
                            polygon::TAIL_WORDS
                        ]
                    );
                    // Banded (sub-edges in the record or apart): the
                    // head, a sub-edge, the probes' bound.
                    for form in [polygon::Form::Banded, polygon::Form::Apart] {
                        let p: Vec<usize> = polygon::kernels(&g, s, form)
                            .iter()
                            .map(|(_, k)| k.fb_reads)
                            .collect();
                        assert_eq!(
                            p,
                            [
                                polygon::HEAD_WORDS,
                                polygon::BAND_EDGE_WORDS,
                                1,
                                1,
                                polygon::TAIL_WORDS
                            ]
                        );
                    }
                    // Each run of a cylinder's or cone's test reads
                    // exactly its field of the record: the body (twice
                    // for glass), a cap's disc.
                    let glass = s == Sides::Both;
                    let l = cylinder::layout(&fit, s, true);
                    let fields = if glass {
                        vec![
                            cylinder::CYL_BODY,
                            cylinder::GCYL_INNER,
                            cylinder::GCYL_CAP0,
                        ]
                    } else {
                        vec![cylinder::CYL_BODY, cylinder::CYL_CAP0]
                    };
                    let k = cylinder::kernels(&g, &fit, s);
                    assert_eq!(k.len(), fields.len());
                    for ((name, k), f) in k.iter().zip(&fields) {
                        assert_eq!(Some(k.fb_reads), l.words_of(*f), "{name} reads {f}");
                    }
                    let l = cone::layout(&fit, s, true);
                    let fields = if glass {
                        vec![cone::CONE_BODY, cone::GCONE_INNER, cone::GCONE_CAP0]
                    } else {
                        vec![cone::CONE_BODY, cone::CONE_CAP0]
                    };
                    let k = cone::kernels(&g, &fit, s);
                    assert_eq!(k.len(), fields.len());
                    for ((name, k), f) in k.iter().zip(&fields) {
                        assert_eq!(Some(k.fb_reads), l.words_of(*f), "{name} reads {f}");
                    }
                }
            }
        }
    }
}

/// A record writer of the 16-bit chip's scene format Q5.10.
fn writer() -> W {
    W::new(1024.0, 10, 0)
}

/// The record written from `start` holds `layout`'s words, and each of its
/// fields begins where the layout puts it.
fn holds_to(w: &W, start: usize, layout: &Layout, what: &str) {
    assert_eq!(w.fb.len() - start, layout.words(), "{what}: words");
    for &(f, n) in &layout.0 {
        if n == 0 {
            continue;
        }
        let at = layout.offset(f).unwrap();
        let mark = w.marks.iter().find(|m| m.0 == f && m.1 >= start);
        assert_eq!(
            mark.map(|m| m.1 - start),
            Some(at),
            "{what}: {f} written at another offset than its layout's"
        );
    }
}

/// Every primitive's writer writes its fields in its layout's order, at
/// its layout's offsets, in every variant: a field moved in the writer
/// and not in the layout (or the header TinyRISC addresses it by) fails.
#[test]
fn every_writer_follows_its_layout() {
    use crate::scene::Vec3;
    let v = |x: f64, y: f64, z: f64| Vec3::new(x, y, z);
    for sphere_fine in [false, true] {
        for fine_normals in [false, true] {
            let fit = Fit {
                sphere_fine,
                fine_normals,
                ..Fit::default()
            };
            let mut w = writer();
            sphere::write(&mut w, &fit, false, v(1.0, 2.0, 3.0), 0.5, false, 7, 1);
            holds_to(&w, 0, &sphere::layout(&fit), "sphere");
            for s in [Sides::Front, Sides::Both] {
                let mut w = writer();
                aabox::write(&mut w, s, v(0.0, 0.0, 0.0), v(1.0, 2.0, 3.0), 7, 1);
                holds_to(&w, 0, &aabox::layout(s), "box");
                let (base, apex) = (v(0.0, 0.0, 0.0), v(0.0, 0.0, 2.0));
                for caps in [false, true] {
                    let discs = cylinder::caps(base, apex, 0.5);
                    let mut w = writer();
                    w.raw(5);
                    let on = caps.then_some((true, &discs));
                    cylinder::write(&mut w, &fit, s, base, apex, 0.5, false, on, 7, 1);
                    holds_to(&w, 1, &cylinder::layout(&fit, s, caps), "cylinder");
                    let cf = cone::ConeFit::of(base, 0.5, apex, 0.25, w.s);
                    let discs = cf.caps(base, 0.5, apex, 0.25, w.s);
                    let fit = Fit { ks_cone: 6, ..fit };
                    let mut w = writer();
                    let on = caps.then_some((true, &discs));
                    cone::write(&mut w, &fit, s, &cf, false, on, 7, 1).unwrap();
                    holds_to(&w, 0, &cone::layout(&fit, s, caps), "cone");
                }
            }
        }
    }
    // The disc, through its primitive: its geometry, then its writer.
    let disc = Shape::from(crate::scene::Disc {
        center: v(1.0, 2.0, 3.0),
        normal: v(0.0, 0.6, 0.8),
        radius: 0.75,
    });
    let p = of_shape(&disc);
    assert_eq!(p.names()[0], "disc");
    let geometry = p.geometry(&disc, writer().s);
    let fit = Fit::default();
    for sides in [Sides::Front, Sides::Both] {
        let o = Object {
            shape: &disc,
            geometry: &geometry,
            fit: &fit,
            sides,
            caps: false,
            size: p.record_words(sides, &fit, 0, false),
            unrounded: false,
            id: 7,
            mat: 1,
        };
        let mut w = writer();
        p.write(&mut w, &o).unwrap();
        holds_to(&w, 0, &p.layout(sides, &fit, 0, false), "disc");
    }
    let tri = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
    let mut w = writer();
    planar::write(&mut w, &[0; 3], &planar::flat_triangle(tri), 7, 1);
    holds_to(&w, 0, &Layout::new(planar::FIELDS), "triangle");
    let mut w = writer();
    let ns = [v(0.0, 0.0, 1.0); 3];
    smooth_triangle::write(&mut w, &[0; 3], &planar::flat_triangle(tri), ns, 7, 1);
    holds_to(
        &w,
        0,
        &Layout::new(smooth_triangle::FIELDS),
        "smooth triangle",
    );
    // A polygon with room for exactly its own edges (a record with room
    // for more is padded after its tail).
    let star: Vec<Vec3> = (0..40)
        .map(|k| {
            let a = k as f64 / 40.0 * std::f64::consts::TAU;
            let r = if k % 2 == 0 { 4.0 } else { 2.0 };
            v(r * a.cos(), r * a.sin(), 0.0)
        })
        .collect();
    let w0 = writer();
    let (_, edges) = polygon::edges(&star, w0.s);
    let fan = edges.len();
    let size = polygon::words(fan, polygon::Form::Plain);
    let mut w = writer();
    polygon::write_as(&mut w, &star, (size, polygon::Form::Plain, None), 7, 1).unwrap();
    holds_to(
        &w,
        0,
        &polygon::layout(fan, polygon::Form::Plain),
        "polygon",
    );
    for form in [polygon::Form::Banded, polygon::Form::Apart] {
        let mut w = writer();
        let size = polygon::words(0, form) + 4096;
        polygon::write_as(&mut w, &star, (size, form, None), 7, 1).unwrap();
        // Up to the sub-edges, whose room is the scene's most.
        let l = polygon::layout(0, form);
        let named: Vec<_> = l.0.iter().filter(|f| f.0.named).copied().collect();
        holds_to_prefix(&w, &Layout(named), form);
    }
}

/// The banded record's named fields before its sub-edges begin where its
/// layout puts them.
fn holds_to_prefix(w: &W, named: &Layout, form: polygon::Form) {
    let full = polygon::layout(0, form);
    for &(f, _) in &named.0 {
        let at = full.offset(f).unwrap();
        let mark = w.marks.iter().find(|m| m.0 == f).map(|m| m.1);
        assert_eq!(
            mark,
            Some(at),
            "{form:?}: {f} written at another offset than its layout's"
        );
    }
}

/// Local positions: the kernels that test an object in a frame of its
/// own read exactly the words their writers write, at their layouts'
/// offsets (the sphere, the flat triangle, the open cylinder and cone).
#[test]
fn every_local_kernel_reads_exactly_its_record() {
    use crate::scene::Vec3;
    let v = Vec3::new;
    let g = Gen {
        datapath: Datapath::W16,
        approx: Approx::default(),
        fine_normals: true,
        test_cuts: true,
        published: false,
    };
    let fit = Fit {
        local: true,
        cyl_local: true,
        cone_local: true,
        fine_normals: true,
        ks_cyll: 6,
        ks_conel: 6,
        ..Fit::default()
    };
    let s = Sides::Front;
    let l = sphere::layout(&fit);
    assert_eq!(sphere::kernel(&g, &fit, s).fb_reads, l.words());
    let mut w = writer();
    sphere::write(&mut w, &fit, false, v(1.0, 2.0, 3.0), 0.5, false, 7, 1);
    holds_to(&w, 0, &l, "local sphere");
    let tri = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
    let n = v(0.0, 0.0, 1.0);
    let shapes = [
        (planar::flat_triangle(tri), Some(&tri)),
        (planar::Planar::rectangle(tri[0], tri[1], tri[2], n), None),
        (planar::Planar::disc(tri[0], tri[1], tri[2], 0.5, n), None),
    ];
    for ((p, vs), two) in shapes.into_iter().flat_map(|x| [(x, false), (x, true)]) {
        let l = triangle_local::layout(two);
        let k = triangle_local::kernel(&g, p.kind, "k", two);
        assert_eq!(k.fb_reads, l.words(), "{:?}, two sides {two}", p.kind);
        let mut w = writer();
        let c = triangle_local::centre(&p, vs);
        triangle_local::write(&mut w, (4, two), c, &p, (7, 1));
        holds_to(&w, 0, &l, "local planar shape");
    }
    let (base, apex) = (v(0.0, 0.0, 0.0), v(0.0, 0.3, 2.0));
    let l = cylinder::layout(&fit, s, false);
    let k = cylinder::kernels(&g, &fit, s);
    assert_eq!((k.len(), k[0].1.fb_reads), (1, l.words()));
    let mut w = writer();
    cylinder_local::write(&mut w, 6, base, apex, 0.5, false, 7, 1);
    holds_to(&w, 0, &l, "local cylinder");
    let l = cone::layout(&fit, s, false);
    let k = cone::kernels(&g, &fit, s);
    assert_eq!((k.len(), k[0].1.fb_reads), (1, l.words()));
    let mut w = writer();
    cone_local::write(&mut w, 12, (base, 0.5), (apex, 0.25), false, 7, 1).unwrap();
    holds_to(&w, 0, &l, "local cone");
}
