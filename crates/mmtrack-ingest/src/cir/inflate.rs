//! A small zlib (RFC 1950) / DEFLATE (RFC 1951) decoder for the compressed
//! variables of MATLAB v5/v7 `.mat` files.
//!
//! Written by hand because the crate has no decompression dependency (see
//! [`super::matlab`]). It follows the structure of Mark Adler's `puff.c`
//! reference decoder: canonical Huffman codes decoded bit by bit from per-length
//! counts. That is slower than a table-driven decoder but short and easy to
//! check; `.mat` channel data is small. Every malformed input is an error, never
//! a panic: reads past the end, over-subscribed codes, codes that are not in
//! the table, back-references before the start of the output, and a wrong
//! Adler-32 checksum.

/// Longest Huffman code in DEFLATE.
const MAX_BITS: usize = 15;
/// Literal/length symbols (0-285, plus two reserved in the fixed code).
const MAX_LIT_LEN_CODES: usize = 288;
/// Distance symbols (0-29, plus two reserved in the fixed code).
const MAX_DIST_CODES: usize = 32;

const LENGTH_BASE: [u16; 29] =
    [3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258];
const LENGTH_EXTRA: [u8; 29] = [0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0];
const DIST_BASE: [u16; 30] = [
    1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145,
    8193, 12289, 16385, 24577,
];
const DIST_EXTRA: [u8; 30] =
    [0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13];
/// Order in which the code-length code lengths are sent.
const CODE_LENGTH_ORDER: [usize; 19] = [16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15];

/// A compressed stream may inflate to at most this many times its size...
pub(crate) const MAX_INFLATE_RATIO: usize = 100;
/// ...beyond this allowance (small inputs of constant data compress far more).
pub(crate) const INFLATE_ALLOWANCE_BYTES: usize = 16 << 20;

/// The most a stream of `compressed_len` bytes may inflate to:
/// [`INFLATE_ALLOWANCE_BYTES`] + [`MAX_INFLATE_RATIO`] x its size, and at
/// most `hard_cap`. Measured channel data compresses 1- to 3-fold; DEFLATE
/// reaches about 1000-fold on constant bytes, so without this bound a 1 MiB
/// file (a decompression bomb, or an array of zeros) would become a 1 GiB
/// buffer and, cut into one-tap snapshots, tens of GB of memory.
pub(crate) fn inflate_limit(compressed_len: usize, hard_cap: usize) -> usize {
    INFLATE_ALLOWANCE_BYTES.saturating_add(compressed_len.saturating_mul(MAX_INFLATE_RATIO)).min(hard_cap)
}

/// What to say when a stream inflates past [`inflate_limit`].
pub(crate) const INFLATE_LIMIT_HINT: &str = "more than 100 times its compressed size beyond the first 16 MiB: \
     a decompression bomb or an array of constants; store such an array uncompressed";

/// Decompresses a zlib stream. `max_output` bounds the decompressed size
/// (the caller knows how much a sane variable can hold). Errors are plain
/// sentences; the caller adds the file and the record.
pub(crate) fn zlib_decompress(input: &[u8], max_output: usize) -> Result<Vec<u8>, String> {
    let [cmf, flg, ..] = *input else {
        return Err("zlib stream shorter than its 2-byte header".into());
    };
    if cmf & 0x0f != 8 || cmf >> 4 > 7 {
        return Err(format!("zlib header byte 0x{cmf:02x}: expected DEFLATE with a window of at most 32 KiB"));
    }
    if (u16::from(cmf) << 8 | u16::from(flg)) % 31 != 0 {
        return Err(format!("zlib header 0x{cmf:02x}{flg:02x} fails its check bits"));
    }
    if flg & 0x20 != 0 {
        return Err("zlib stream needs a preset dictionary, which .mat files never use".into());
    }
    let mut bits = BitReader { data: input, pos: 2, bit_buf: 0, bit_count: 0 };
    let output = inflate(&mut bits, max_output)?;
    let trailer_at = bits.byte_aligned_pos();
    let Some(trailer) = input.get(trailer_at..trailer_at + 4) else {
        return Err("zlib stream ends before its Adler-32 checksum".into());
    };
    let expected = u32::from_be_bytes([trailer[0], trailer[1], trailer[2], trailer[3]]);
    let found = adler32(&output);
    if expected != found {
        return Err(format!("Adler-32 checksum 0x{found:08x} of the decompressed data, expected 0x{expected:08x}"));
    }
    Ok(output)
}

/// Decompresses a raw DEFLATE stream (no zlib header or checksum; ZIP
/// members, whose CRC-32 the caller checks).
pub(crate) fn inflate_raw(input: &[u8], max_output: usize) -> Result<Vec<u8>, String> {
    let mut bits = BitReader { data: input, pos: 0, bit_buf: 0, bit_count: 0 };
    inflate(&mut bits, max_output)
}

pub(super) fn adler32(data: &[u8]) -> u32 {
    const MOD: u32 = 65_521;
    let (mut a, mut b) = (1u32, 0u32);
    // 5552 is the largest run for which `b` cannot overflow u32 before the modulo.
    for chunk in data.chunks(5552) {
        for &byte in chunk {
            a += u32::from(byte);
            b += a;
        }
        a %= MOD;
        b %= MOD;
    }
    b << 16 | a
}

struct BitReader<'a> {
    data: &'a [u8],
    /// Next byte to load.
    pos: usize,
    bit_buf: u32,
    bit_count: u32,
}

impl BitReader<'_> {
    /// Reads `n` (at most 16) bits, least significant first.
    fn bits(&mut self, n: u32) -> Result<u32, String> {
        while self.bit_count < n {
            let Some(&byte) = self.data.get(self.pos) else {
                return Err("compressed data ends in the middle of a block".into());
            };
            self.pos += 1;
            self.bit_buf |= u32::from(byte) << self.bit_count;
            self.bit_count += 8;
        }
        let value = self.bit_buf & ((1u32 << n) - 1);
        self.bit_buf >>= n;
        self.bit_count -= n;
        Ok(value)
    }

    /// Drops the bits left in the current byte.
    fn align(&mut self) {
        self.bit_buf = 0;
        self.bit_count = 0;
    }

    /// Position of the first byte not yet (even partly) consumed.
    fn byte_aligned_pos(&self) -> usize {
        // Whole unread bytes still in the buffer go back to the stream.
        self.pos - (self.bit_count / 8) as usize
    }
}

/// A canonical Huffman code: how many codes of each length, and the symbols
/// ordered by code.
struct Huffman {
    count: [u16; MAX_BITS + 1],
    symbol: Vec<u16>,
}

impl Huffman {
    /// Builds the code from per-symbol code lengths (0 = unused). Incomplete
    /// codes are accepted (a code not in the table fails when decoded);
    /// over-subscribed ones are not.
    fn new(lengths: &[u8]) -> Result<Self, String> {
        let mut count = [0u16; MAX_BITS + 1];
        for &len in lengths {
            count[usize::from(len)] += 1;
        }
        let mut left: i32 = 1;
        for &c in &count[1..] {
            left = (left << 1) - i32::from(c);
            if left < 0 {
                return Err("over-subscribed Huffman code".into());
            }
        }
        let mut offsets = [0u16; MAX_BITS + 2];
        for len in 1..=MAX_BITS {
            offsets[len + 1] = offsets[len] + count[len];
        }
        let mut symbol = vec![0u16; lengths.len()];
        for (sym, &len) in lengths.iter().enumerate() {
            if len != 0 {
                let slot = &mut offsets[usize::from(len)];
                symbol[usize::from(*slot)] = sym as u16;
                *slot += 1;
            }
        }
        Ok(Self { count, symbol })
    }

    fn decode(&self, bits: &mut BitReader<'_>) -> Result<u16, String> {
        let (mut code, mut first, mut index) = (0i32, 0i32, 0i32);
        for len in 1..=MAX_BITS {
            code |= bits.bits(1)? as i32;
            let count = i32::from(self.count[len]);
            if code - first < count {
                return self
                    .symbol
                    .get((index + code - first) as usize)
                    .copied()
                    .ok_or_else(|| "Huffman table inconsistent".to_string());
            }
            index += count;
            first = (first + count) << 1;
            code <<= 1;
        }
        Err("bit pattern that is not a code of the block's Huffman table".into())
    }
}

fn inflate(bits: &mut BitReader<'_>, max_output: usize) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    loop {
        let last = bits.bits(1)? == 1;
        match bits.bits(2)? {
            0 => stored(bits, &mut out, max_output)?,
            1 => {
                let (lit_len, dist) = fixed_codes()?;
                codes(bits, &mut out, &lit_len, &dist, max_output)?;
            }
            2 => {
                let (lit_len, dist) = dynamic_codes(bits)?;
                codes(bits, &mut out, &lit_len, &dist, max_output)?;
            }
            _ => return Err("DEFLATE block of reserved type 3".into()),
        }
        if last {
            return Ok(out);
        }
    }
}

fn stored(bits: &mut BitReader<'_>, out: &mut Vec<u8>, max_output: usize) -> Result<(), String> {
    bits.align();
    let pos = bits.pos;
    let Some(header) = bits.data.get(pos..pos + 4) else {
        return Err("stored block ends before its length".into());
    };
    let len = u16::from_le_bytes([header[0], header[1]]);
    let nlen = u16::from_le_bytes([header[2], header[3]]);
    if len != !nlen {
        return Err(format!("stored block length {len} does not match its complement {nlen}"));
    }
    let start = pos + 4;
    let Some(data) = bits.data.get(start..start + usize::from(len)) else {
        return Err(format!("stored block promises {len} bytes, fewer remain"));
    };
    if out.len() + data.len() > max_output {
        return Err(format!("decompresses to more than {max_output} bytes"));
    }
    out.extend_from_slice(data);
    bits.pos = start + usize::from(len);
    Ok(())
}

fn fixed_codes() -> Result<(Huffman, Huffman), String> {
    let mut lengths = [0u8; MAX_LIT_LEN_CODES];
    lengths[..144].fill(8);
    lengths[144..256].fill(9);
    lengths[256..280].fill(7);
    lengths[280..].fill(8);
    Ok((Huffman::new(&lengths)?, Huffman::new(&[5u8; MAX_DIST_CODES])?))
}

fn dynamic_codes(bits: &mut BitReader<'_>) -> Result<(Huffman, Huffman), String> {
    let n_lit_len = bits.bits(5)? as usize + 257;
    let n_dist = bits.bits(5)? as usize + 1;
    let n_code_len = bits.bits(4)? as usize + 4;
    if n_lit_len > 286 || n_dist > 30 {
        return Err(format!("dynamic block declares {n_lit_len} length and {n_dist} distance codes (max 286, 30)"));
    }
    let mut code_len_lengths = [0u8; 19];
    for &index in &CODE_LENGTH_ORDER[..n_code_len] {
        code_len_lengths[index] = bits.bits(3)? as u8;
    }
    let code_len_code = Huffman::new(&code_len_lengths)?;
    let mut lengths = [0u8; MAX_LIT_LEN_CODES + MAX_DIST_CODES];
    let total = n_lit_len + n_dist;
    let mut i = 0;
    while i < total {
        let symbol = code_len_code.decode(bits)?;
        if symbol < 16 {
            lengths[i] = symbol as u8;
            i += 1;
            continue;
        }
        let (value, repeat) = match symbol {
            16 => {
                let Some(previous) = i.checked_sub(1).map(|p| lengths[p]) else {
                    return Err("code-length repeat with no previous length".into());
                };
                (previous, 3 + bits.bits(2)? as usize)
            }
            17 => (0, 3 + bits.bits(3)? as usize),
            _ => (0, 11 + bits.bits(7)? as usize),
        };
        if i + repeat > total {
            return Err("code-length repeat runs past the declared code count".into());
        }
        lengths[i..i + repeat].fill(value);
        i += repeat;
    }
    if lengths[256] == 0 {
        return Err("dynamic block has no end-of-block code".into());
    }
    Ok((Huffman::new(&lengths[..n_lit_len])?, Huffman::new(&lengths[n_lit_len..total])?))
}

fn codes(
    bits: &mut BitReader<'_>,
    out: &mut Vec<u8>,
    lit_len: &Huffman,
    dist: &Huffman,
    max_output: usize,
) -> Result<(), String> {
    loop {
        let symbol = usize::from(lit_len.decode(bits)?);
        if symbol < 256 {
            if out.len() >= max_output {
                return Err(format!("decompresses to more than {max_output} bytes"));
            }
            out.push(symbol as u8);
            continue;
        }
        if symbol == 256 {
            return Ok(());
        }
        let index = symbol - 257;
        let (Some(&base), Some(&extra)) = (LENGTH_BASE.get(index), LENGTH_EXTRA.get(index)) else {
            return Err(format!("invalid length symbol {symbol}"));
        };
        let len = usize::from(base) + bits.bits(u32::from(extra))? as usize;
        let dist_symbol = usize::from(dist.decode(bits)?);
        let (Some(&base), Some(&extra)) = (DIST_BASE.get(dist_symbol), DIST_EXTRA.get(dist_symbol)) else {
            return Err(format!("invalid distance symbol {dist_symbol}"));
        };
        let distance = usize::from(base) + bits.bits(u32::from(extra))? as usize;
        if distance > out.len() {
            return Err(format!("back-reference {distance} bytes before the start of the output"));
        }
        if out.len() + len > max_output {
            return Err(format!("decompresses to more than {max_output} bytes"));
        }
        // Byte by byte: the source may overlap what is being written.
        let start = out.len() - distance;
        for k in 0..len {
            let byte = out[start + k];
            out.push(byte);
        }
    }
}

/// A raw DEFLATE stream of `1 + 258 * matches` zero bytes in one fixed
/// Huffman block (a literal 0, then matches of length 258 at distance 1):
/// about 160-fold compression, for tests of [`inflate_limit`].
#[cfg(test)]
pub(crate) fn zeros_deflated(matches: usize) -> Vec<u8> {
    let (mut out, mut acc, mut n) = (Vec::new(), 0u64, 0u32);
    // Appends `count` bits of `value`, most significant first (Huffman codes)
    // or least significant first (header fields).
    let mut push = |value: u32, count: u32, msb_first: bool| {
        for i in 0..count {
            let bit = if msb_first { value >> (count - 1 - i) } else { value >> i } & 1;
            acc |= u64::from(bit) << n;
            n += 1;
            if n == 8 {
                out.push(acc as u8);
                (acc, n) = (0, 0);
            }
        }
    };
    push(1, 1, false); // BFINAL
    push(1, 2, false); // BTYPE fixed
    push(0x30, 8, true); // literal 0
    for _ in 0..matches {
        push(0xc5, 8, true); // length symbol 285: 258
        push(0, 5, true); // distance symbol 0: 1
    }
    push(0, 7, true); // end of block
    push(0, 7, false); // pad to a byte
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hex(text: &str) -> Vec<u8> {
        (0..text.len()).step_by(2).map(|i| u8::from_str_radix(&text[i..i + 2], 16).unwrap()).collect()
    }

    // Streams made with Python's zlib.compress (CPython 3, zlib 1.2/1.3).
    #[test]
    fn fixed_dynamic_and_stored_blocks_decode() {
        // zlib.compress(b"hello hello hello hello", 9): one fixed-Huffman block with a back-reference.
        let fixed = hex("78dacb48cdc9c957c8402701680308b1");
        assert_eq!(zlib_decompress(&fixed, 1 << 20).unwrap(), b"hello hello hello hello");
        // zlib.compress(b"abc", 0): a stored block.
        let stored = hex("7801010300fcff616263024d0127");
        assert_eq!(zlib_decompress(&stored, 1 << 20).unwrap(), b"abc");
        // zlib.compress(b"the quick brown fox jumps over the lazy dog; " * 4 + bytes(range(97, 123)) * 3, 9):
        // a dynamic-Huffman block (block type bits 2).
        let expected: Vec<u8> = b"the quick brown fox jumps over the lazy dog; "
            .repeat(4)
            .into_iter()
            .chain((0..3).flat_map(|_| 97..123u8))
            .collect();
        let dynamic = hex(DYNAMIC_HEX);
        assert_eq!((dynamic[2] >> 1) & 3, 2);
        assert_eq!(zlib_decompress(&dynamic, 1 << 20).unwrap(), expected);
    }

    const DYNAMIC_HEX: &str = concat!(
        "78dacdcab71180301000c156be0faa91f77a79573d0c251011deec352d2077c31cd0823382c405b68754018728d01e",
        "f6e46ce0a8aeb77e3013cab8904a1beb7c889872a9ad8fb9f6f922373da862ae"
    );

    #[test]
    fn corrupt_streams_are_errors() {
        let fixed = hex("78dacb48cdc9c957c8402701680308b1");
        for cut in 0..fixed.len() {
            assert!(zlib_decompress(&fixed[..cut], 1 << 20).is_err(), "cut at {cut}");
        }
        let mut bad_sum = fixed.clone();
        let last = bad_sum.len() - 1;
        bad_sum[last] ^= 1;
        assert!(zlib_decompress(&bad_sum, 1 << 20).unwrap_err().contains("Adler-32"));
        assert!(zlib_decompress(&fixed, 5).unwrap_err().contains("more than 5 bytes"));
        assert_eq!(inflate_raw(&zeros_deflated(3), 1 << 20).unwrap(), vec![0; 1 + 3 * 258]);
        assert_eq!(inflate_limit(1000, usize::MAX), (16 << 20) + 100_000);
        assert_eq!(inflate_limit(usize::MAX, 1 << 31), 1 << 31);
        assert!(zlib_decompress(&hex("7801"), 1 << 20).is_err());
        assert!(zlib_decompress(&hex("78da"), 1 << 20).unwrap_err().contains("ends"));
        assert!(zlib_decompress(&hex("7802"), 1 << 20).unwrap_err().contains("check bits"));
        // Reserved block type 3.
        assert!(zlib_decompress(&hex("7801070000"), 1 << 20).unwrap_err().contains("reserved"));
    }

    #[test]
    fn adler32_matches_the_rfc_example() {
        // RFC 1950 / Wikipedia: adler32("Wikipedia") = 0x11E60398.
        assert_eq!(adler32(b"Wikipedia"), 0x11E6_0398);
        assert_eq!(adler32(&[0xff; 100_000]), adler32_naive(&[0xff; 100_000]));
    }

    fn adler32_naive(data: &[u8]) -> u32 {
        let (mut a, mut b) = (1u64, 0u64);
        for &byte in data {
            a = (a + u64::from(byte)) % 65_521;
            b = (b + a) % 65_521;
        }
        (b << 16 | a) as u32
    }
}
