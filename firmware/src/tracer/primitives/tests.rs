//! The primitives' records, kernels and table held against each other.

use super::*;

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
                    // Caps flag (read by TinyRISC), the body runs, two
                    // caps; without caps, the body runs alone.
                    let cyl: usize = cylinder::kernels(&g, &fit, s)
                        .iter()
                        .map(|(_, k)| k.fb_reads)
                        .sum();
                    assert_eq!(1 + cyl + planar::WORDS, cylinder::words(&fit, s, true));
                    assert_eq!(cyl - planar::WORDS, cylinder::words(&fit, s, false));
                    let cone: usize = cone::kernels(&g, s).iter().map(|(_, k)| k.fb_reads).sum();
                    assert_eq!(1 + cone + planar::WORDS, cone::words(s, true));
                    assert_eq!(cone - planar::WORDS, cone::words(s, false));
                }
            }
        }
    }
}
