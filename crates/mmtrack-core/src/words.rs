//! Counts and rates in the words of a summary line: "1 set", "2 sets", "3.2/s".

/// `n` and the noun in its number: `counted(1, "set")` is "1 set",
/// `counted(2, "set")` "2 sets" (nouns whose plural is not `+s` take
/// [`counted_as`]).
#[must_use]
pub fn counted(n: impl Into<u64>, noun: &str) -> String {
    let n = n.into();
    if n == 1 { format!("1 {noun}") } else { format!("{n} {noun}s") }
}

/// `n` with `one` or `many`: `counted_as(2, "entry", "entries")`.
#[must_use]
pub fn counted_as(n: impl Into<u64>, one: &str, many: &str) -> String {
    let n = n.into();
    if n == 1 { format!("1 {one}") } else { format!("{n} {many}") }
}

/// Items per second as a person reads it: "3.2/s", "361/s" (a progress
/// bar's own rate prints "3.2071/s"); "-/s" before there is a rate.
#[must_use]
pub fn rate_per_s(per_sec: f64) -> String {
    if !per_sec.is_finite() || per_sec <= 0.0 {
        "-/s".to_string()
    } else if per_sec < 10.0 {
        format!("{per_sec:.1}/s")
    } else {
        format!("{per_sec:.0}/s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_is_singular_and_everything_else_plural() {
        assert_eq!(counted(1u32, "set"), "1 set");
        assert_eq!(counted(0u32, "set"), "0 sets");
        assert_eq!(counted(17u64, "reception"), "17 receptions");
        assert_eq!(counted_as(1u8, "entry", "entries"), "1 entry");
        assert_eq!(counted_as(3u8, "entry", "entries"), "3 entries");
    }

    #[test]
    fn rates_read_as_a_person_reads_them() {
        assert_eq!(rate_per_s(3.207_123), "3.2/s");
        assert_eq!(rate_per_s(361.4), "361/s");
        assert_eq!(rate_per_s(0.0), "-/s");
        assert_eq!(rate_per_s(f64::NAN), "-/s");
    }
}
