//! Kuhn-Munkres known answers.

use mmtrack_filter::assignment::{solve, solve_with_unassigned};

use crate::support::m;

/// The classic 3x3 example: rows -> cols (0 -> 1, 1 -> 0, 2 -> 2), cost 1 + 2 + 2 = 5.
#[test]
fn three_by_three() {
    let c = m(3, 3, &[4.0, 1.0, 3.0, 2.0, 0.0, 5.0, 3.0, 2.0, 2.0]);
    let a = solve(&c).expect("finite");
    assert_eq!(a.row_to_col, vec![Some(1), Some(0), Some(2)]);
    assert_eq!(a.total_cost, 5.0);
}

/// More rows than columns: the row that costs most to pair stays unpaired.
#[test]
fn tall_matrix() {
    let c = m(3, 2, &[1.0, 9.0, 9.0, 1.0, 5.0, 5.0]);
    let a = solve(&c).expect("finite");
    assert_eq!(a.row_to_col, vec![Some(0), Some(1), None]);
    assert_eq!(a.total_cost, 2.0);
}

/// Forbidden pairs (+inf) and an unassigned cost of 3: row 0 takes column 0
/// (1), row 1's only allowed pair costs 4 > 3 so it stays unpaired (3); total 4.
#[test]
fn unassigned_and_forbidden() {
    let c = m(2, 2, &[1.0, f64::INFINITY, f64::INFINITY, 4.0]);
    let a = solve_with_unassigned(&c, 3.0).expect("valid");
    assert_eq!(a.row_to_col, vec![Some(0), None]);
    assert_eq!(a.total_cost, 4.0);
    assert!(solve_with_unassigned(&c, f64::NAN).is_err());
    assert!(solve(&c).is_err(), "plain solve needs finite costs");
}
