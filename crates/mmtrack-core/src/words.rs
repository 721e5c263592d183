//! Counts in the words of a summary line: "1 set", "2 sets".

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
}
