//! Byte mutations of a seeded PCG stream: the same seed gives the same inputs.
//!
//! Each new input is a corpus entry changed by 1, 2, 4 or 8 stacked
//! mutations (half of them by one): bit flips; bytes and 16/32/64-bit words (both byte orders) set
//! to boundary values (0, 0x7f.., 0x80.., 0xff.., the input's own length);
//! small additions; inserted, deleted and duplicated ranges; a splice with
//! another entry; truncation; and, for the text formats, a run of ASCII
//! digits replaced by a boundary number (`-1`, `4294967296`, `2^62`, `1e308`,
//! `nan`).

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;

const BYTES: [u8; 10] = [0, 1, 0x7f, 0x80, 0xff, 0x10, 0x20, 0x40, 0x64, 0xfe];
const WORDS: [u64; 16] = [
    0,
    1,
    0x7f,
    0x80,
    0xff,
    0x7fff,
    0x8000,
    0xffff,
    0x1_0000,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
    0x1_0000_0000,
    0x7fff_ffff_ffff_ffff,
    0x8000_0000_0000_0000,
    u64::MAX,
];
const NUMBERS: [&str; 23] = [
    "0",
    "-1",
    "1",
    "2",
    "255",
    "65535",
    "65536",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "9007199254740993",
    "4611686018427387904",
    "6148914691236517206",
    "9223372036854775807",
    "18446744073709551616",
    "99999999999999999999999999",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-0",
    "",
];

/// Makes new inputs from old ones.
pub struct Mutator {
    rng: Pcg64,
    max_len: usize,
}

impl Mutator {
    /// A mutator whose inputs are at most `max_len` bytes.
    #[must_use]
    pub fn new(seed: u64, max_len: usize) -> Self {
        Self { rng: Pcg64::seed_from_u64(seed), max_len }
    }

    /// A uniform index below `n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 { 0 } else { self.rng.random_range(0..n) }
    }

    /// Writes into `out` the input `base` changed by 1 to 8 mutations;
    /// `other` is the partner of a splice.
    pub fn mutate(&mut self, base: &[u8], other: &[u8], out: &mut Vec<u8>) {
        out.clear();
        out.extend_from_slice(base);
        // Mostly one or two changes: a stack of eight rarely leaves a
        // format readable far enough to test its later checks.
        let count = match self.below(8) {
            0..=3 => 1,
            4 | 5 => 2,
            6 => 4,
            _ => 8,
        };
        for _ in 0..count {
            self.mutate_once(out, other);
        }
        out.truncate(self.max_len);
    }

    fn mutate_once(&mut self, data: &mut Vec<u8>, other: &[u8]) {
        let len = data.len();
        let at = self.below(len);
        match self.below(12) {
            0 if len > 0 => data[at] ^= 1 << self.below(8),
            1 if len > 0 => data[at] = BYTES[self.below(BYTES.len())],
            2 if len > 0 => data[at] = self.rng.random(),
            3 => self.write_word(data),
            4 if len > 0 => {
                // Add or subtract 1 to 16.
                let delta = self.rng.random_range(1..=16u8);
                data[at] = if self.rng.random() { data[at].wrapping_add(delta) } else { data[at].wrapping_sub(delta) };
            }
            5 => {
                let longest = if self.rng.random() { 8 } else { 512 };
                let count = 1 + self.below(longest);
                let byte = if self.rng.random() { BYTES[self.below(BYTES.len())] } else { self.rng.random() };
                let random = self.rng.random::<bool>();
                let fill: Vec<u8> = (0..count).map(|_| if random { self.rng.random() } else { byte }).collect();
                data.splice(at..at, fill);
            }
            6 if len > 0 => {
                let count = 1 + self.below((len - at).min(1 + len / 4));
                data.drain(at..at + count);
            }
            7 if len > 0 => {
                let count = 1 + self.below((len - at).min(1024));
                let chunk = data[at..at + count].to_vec();
                let to = self.below(len + 1);
                data.splice(to..to, chunk);
            }
            8 if !other.is_empty() => {
                let from = self.below(other.len());
                if self.rng.random() {
                    data.truncate(at);
                    data.extend_from_slice(&other[from..]);
                } else {
                    let count = 1 + self.below((other.len() - from).min(256));
                    data.splice(at..at, other[from..from + count].iter().copied());
                }
            }
            9 if len > 0 => data.truncate(at),
            10 | 11 => self.replace_number(data),
            _ => {}
        }
    }

    /// A boundary value (or the input's length, plus or minus one) as a
    /// 2-, 4- or 8-byte word in either byte order.
    fn write_word(&mut self, data: &mut [u8]) {
        let width = [2, 4, 8][self.below(3)];
        if data.len() < width {
            return;
        }
        let at = self.below(data.len() - width + 1);
        let value = match self.below(4) {
            0 => (data.len() as u64).wrapping_add(self.below(3) as u64).wrapping_sub(1),
            _ => WORDS[self.below(WORDS.len())],
        };
        // The low `width` bytes of the value, in the chosen order.
        if self.rng.random() {
            data[at..at + width].copy_from_slice(&value.to_le_bytes()[..width]);
        } else {
            data[at..at + width].copy_from_slice(&value.to_be_bytes()[8 - width..]);
        }
    }

    /// Replaces the first run of ASCII digits at or after a random position
    /// with a boundary number.
    fn replace_number(&mut self, data: &mut Vec<u8>) {
        let from = self.below(data.len());
        let Some(start) = data[from..].iter().position(u8::is_ascii_digit).map(|p| from + p) else {
            return;
        };
        let end = data[start..].iter().position(|b| !b.is_ascii_digit()).map_or(data.len(), |p| start + p);
        let number = NUMBERS[self.below(NUMBERS.len())];
        data.splice(start..end, number.bytes());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_inputs_and_the_length_bound_holds() {
        let base = b"$GPGGA,123519,4807.038,N*47\r\n".repeat(4);
        let (mut a, mut b) = (Mutator::new(7, 256), Mutator::new(7, 256));
        let (mut out_a, mut out_b) = (Vec::new(), Vec::new());
        let mut changed = 0;
        for _ in 0..2000 {
            a.mutate(&base, b"other", &mut out_a);
            b.mutate(&base, b"other", &mut out_b);
            assert_eq!(out_a, out_b);
            assert!(out_a.len() <= 256);
            changed += usize::from(out_a != base);
        }
        // Nearly every stack of mutations changes something; 1900 of 2000
        // leaves room for the few that undo themselves or do nothing.
        assert!(changed > 1900, "{changed} of 2000 inputs changed");
    }
}
