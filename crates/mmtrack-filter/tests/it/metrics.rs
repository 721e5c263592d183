//! OSPA and GOSPA against values computed by hand.

use mmtrack_filter::metrics::{gospa, ospa};

use crate::support::v;

/// Hand-computed values are short sums and one square root; 1e-12 absorbs the
/// rounding of `powf`.
const TOL: f64 = 1e-12;

#[test]
fn single_pair_inside_the_cut_off() {
    let (x, y) = (vec![v(&[0.0])], vec![v(&[3.0])]);
    assert!((ospa(&x, &y, 10.0, 1.0).expect("valid").distance - 3.0).abs() < TOL);
    let g = gospa(&x, &y, 10.0, 1.0).expect("valid");
    assert!((g.distance - 3.0).abs() < TOL);
    assert_eq!((g.missed, g.false_targets), (0, 0));
}

/// X = {0, 10}, Y = {1}, c = 5, p = 2.
/// OSPA: n = 2, best pair (0, 1) at 1: sqrt((1 + 25) / 2) = sqrt(13).
/// GOSPA: sqrt(1 + 25 / 2) = sqrt(13.5), one missed target.
#[test]
fn cardinality_mismatch() {
    let (x, y) = (vec![v(&[0.0]), v(&[10.0])], vec![v(&[1.0])]);
    let o = ospa(&x, &y, 5.0, 2.0).expect("valid");
    assert!((o.distance - 13.0_f64.sqrt()).abs() < TOL);
    assert!((o.localisation - 0.5_f64.sqrt()).abs() < TOL);
    assert!((o.cardinality - 12.5_f64.sqrt()).abs() < TOL);
    // Symmetric.
    assert!((ospa(&y, &x, 5.0, 2.0).expect("valid").distance - o.distance).abs() < TOL);
    let g = gospa(&x, &y, 5.0, 2.0).expect("valid");
    assert!((g.distance - 13.5_f64.sqrt()).abs() < TOL);
    assert_eq!((g.missed, g.false_targets), (1, 0));
    assert!((g.localisation_p - 1.0).abs() < TOL);
}

/// A pair farther apart than c: OSPA = c; GOSPA counts one missed and one
/// false target, sqrt(2 * 25 / 2) = 5.
#[test]
fn pair_beyond_the_cut_off() {
    let (x, y) = (vec![v(&[0.0])], vec![v(&[100.0])]);
    assert!((ospa(&x, &y, 5.0, 2.0).expect("valid").distance - 5.0).abs() < TOL);
    let g = gospa(&x, &y, 5.0, 2.0).expect("valid");
    assert!((g.distance - 5.0).abs() < TOL);
    assert_eq!((g.missed, g.false_targets), (1, 1));
}

/// Empty sets: both empty is 0; one empty is c for OSPA and
/// (3 c^p / 2)^(1/p) = sqrt(3 * 4 / 2) = sqrt(6) for GOSPA (c = 2, p = 2).
#[test]
fn empty_sets() {
    let none: Vec<_> = Vec::new();
    let three = vec![v(&[0.0, 0.0]), v(&[1.0, 0.0]), v(&[0.0, 1.0])];
    assert_eq!(ospa(&none, &none, 2.0, 2.0).expect("valid").distance, 0.0);
    assert_eq!(gospa(&none, &none, 2.0, 2.0).expect("valid").distance, 0.0);
    assert!((ospa(&none, &three, 2.0, 2.0).expect("valid").distance - 2.0).abs() < TOL);
    let g = gospa(&three, &none, 2.0, 2.0).expect("valid");
    assert!((g.distance - 6.0_f64.sqrt()).abs() < TOL);
    assert_eq!((g.missed, g.false_targets), (3, 0));
}

/// 2-D, the optimal pairing is not the listed order:
/// X = {(0,0), (10,0)}, Y = {(10,2), (0,1)}, c = 100, p = 1:
/// pairs at 1 and 2, OSPA = 3 / 2, GOSPA = 3.
#[test]
fn two_dimensional_optimal_pairing() {
    let x = vec![v(&[0.0, 0.0]), v(&[10.0, 0.0])];
    let y = vec![v(&[10.0, 2.0]), v(&[0.0, 1.0])];
    assert!((ospa(&x, &y, 100.0, 1.0).expect("valid").distance - 1.5).abs() < TOL);
    assert!((gospa(&x, &y, 100.0, 1.0).expect("valid").distance - 3.0).abs() < TOL);
}
