//! Bounded zlib (RFC 1950) and raw DEFLATE (RFC 1951) decompression for the
//! compressed variables of MATLAB v5/v7 `.mat` files and the deflated members
//! of `.npz` archives, with `miniz_oxide` (the inflater the `png` crate already
//! brings into the build). What is ours is the bound on the output
//! ([`inflate_limit`]: decompression bombs) and the error sentences; the caller
//! adds the file, the record and the field.

use miniz_oxide::inflate::{
    DecompressError, TINFLStatus, decompress_to_vec_with_limit, decompress_to_vec_zlib_with_limit,
};

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

/// Decompresses a zlib stream and checks its Adler-32. `max_output` bounds
/// the decompressed size (the caller knows how much a sane variable can
/// hold); the output buffer never grows past it. Errors are plain sentences.
pub(crate) fn zlib_decompress(input: &[u8], max_output: usize) -> Result<Vec<u8>, String> {
    decompress_to_vec_zlib_with_limit(input, max_output).map_err(|e| describe(&e, "zlib", max_output))
}

/// Decompresses a raw DEFLATE stream (no zlib header or checksum; ZIP
/// members, whose CRC-32 the caller checks), bounded as [`zlib_decompress`].
pub(crate) fn inflate_raw(input: &[u8], max_output: usize) -> Result<Vec<u8>, String> {
    decompress_to_vec_with_limit(input, max_output).map_err(|e| describe(&e, "DEFLATE", max_output))
}

/// `miniz_oxide` reports a status, not where or why a stream is corrupt.
fn describe(error: &DecompressError, stream: &str, max_output: usize) -> String {
    match error.status {
        TINFLStatus::HasMoreOutput => format!("decompresses to more than {max_output} bytes"),
        TINFLStatus::FailedCannotMakeProgress | TINFLStatus::NeedsMoreInput => {
            format!("truncated {stream} stream: the data ends before the stream's last block (or checksum) does")
        }
        TINFLStatus::Adler32Mismatch => "Adler-32 checksum of the decompressed data does not match the stream's".into(),
        TINFLStatus::Failed => format!(
            "corrupt {stream} stream (a bad header, a reserved block type, an invalid Huffman code or a \
             back-reference before the start of the data)"
        ),
        other => format!("{stream} decompression failed ({other:?})"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use miniz_oxide::deflate::{compress_to_vec, compress_to_vec_zlib};

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

    /// npz members are inflated with the limit set to the size their
    /// directory entry declares: a stream of exactly that size must pass.
    #[test]
    fn a_limit_equal_to_the_output_size_is_enough() {
        for len in [0, 1, 257, 65_535, 65_536, 300_001] {
            let data: Vec<u8> = (0..len).map(|i| (i * 7 % 251) as u8).collect();
            for level in [0, 1, 6, 10] {
                assert_eq!(inflate_raw(&compress_to_vec(&data, level), len).unwrap(), data, "{len}, {level}");
                assert_eq!(zlib_decompress(&compress_to_vec_zlib(&data, level), len).unwrap(), data, "{len}");
                if len > 0 {
                    let e = inflate_raw(&compress_to_vec(&data, level), len - 1).unwrap_err();
                    assert_eq!(e, format!("decompresses to more than {} bytes", len - 1));
                }
            }
        }
    }

    #[test]
    fn corrupt_streams_are_errors() {
        let fixed = hex("78dacb48cdc9c957c8402701680308b1");
        for cut in 0..fixed.len() {
            assert!(zlib_decompress(&fixed[..cut], 1 << 20).is_err(), "cut at {cut}");
        }
        assert!(zlib_decompress(&fixed[..10], 1 << 20).unwrap_err().contains("truncated"));
        let mut bad_sum = fixed.clone();
        let last = bad_sum.len() - 1;
        bad_sum[last] ^= 1;
        assert!(zlib_decompress(&bad_sum, 1 << 20).unwrap_err().contains("Adler-32"));
        assert!(zlib_decompress(&fixed, 5).unwrap_err().contains("more than 5 bytes"));
        assert_eq!(inflate_limit(1000, usize::MAX), (16 << 20) + 100_000);
        assert_eq!(inflate_limit(usize::MAX, 1 << 31), 1 << 31);
        assert!(zlib_decompress(&hex("7801"), 1 << 20).is_err());
        // Bad check bits, a preset dictionary, compression method 9 (not DEFLATE).
        for header in ["7802", "78bb", "7918"] {
            assert!(zlib_decompress(&hex(header), 1 << 20).unwrap_err().contains("corrupt zlib"), "{header}");
        }
        // Reserved block type 3.
        assert!(zlib_decompress(&hex("7801070000"), 1 << 20).unwrap_err().contains("corrupt zlib"));
        assert!(inflate_raw(&hex("07"), 1 << 20).unwrap_err().contains("corrupt DEFLATE"));
        // A back-reference before the start of the output: a fixed-Huffman block
        // whose first symbol is a match (length 3, distance 1).
        assert!(inflate_raw(&hex("03020000"), 1 << 20).unwrap_err().contains("corrupt DEFLATE"));
    }

    /// The bound holds while inflating, whatever the stream claims: 32 MiB
    /// of zeros deflate about 1000-fold, past the 100-fold limit.
    #[test]
    fn a_stream_inflating_past_its_limit_is_refused() {
        let zeros = vec![0u8; 32 << 20];
        for (stream, compressed) in [("zlib", compress_to_vec_zlib(&zeros, 6)), ("raw", compress_to_vec(&zeros, 6))] {
            let limit = inflate_limit(compressed.len(), usize::MAX);
            assert!(limit < zeros.len(), "{stream}: {} compressed bytes", compressed.len());
            let e =
                if stream == "zlib" { zlib_decompress(&compressed, limit) } else { inflate_raw(&compressed, limit) };
            assert_eq!(e.unwrap_err(), format!("decompresses to more than {limit} bytes"));
        }
    }
}
