//! Decoding of 8-bit greyscale PNGs (Navtech polar scans), header first, with
//! errors that say what was wrong with the image rather than panicking.
//!
//! Memory: a decode holds one buffer of the image's size (pixels plus one
//! filter byte per row; the filters are undone in place) and, for a file
//! ([`Gray8Png::open_file`]), buffers of 64 KiB, never the whole file; decodes
//! running at once share a budget of one [`MAX_GRAY8_BYTES`] image, so
//! images near the cap (PNG bombs included) decode one at a time.
//!
//! [`Gray8Png::open`] reads only the header (and the chunks before the image
//! data), so a caller checks the dimensions against what it expects before a
//! single pixel is allocated; [`Gray8Png::decode`] refuses images over
//! [`MAX_GRAY8_BYTES`] whatever the caller checked.
//!
//! The `png` crate parses the signature, the header and the chunks and checks
//! every chunk CRC. The image data is inflated here with `fdeflate` (the
//! inflater the `png` crate uses) and unfiltered here, because the `png`
//! decoder does not verify the zlib stream: it checks the Adler-32 only when
//! its inflater happens to reach the stream's end before the pixels are full,
//! and accepts a stream that runs on past them, so a corrupted scan could
//! decode as a good one. Here the stream must end exactly after the last
//! pixel row with a matching Adler-32.

use std::fs::File;
use std::io::{BufRead, BufReader, Cursor, Read, Seek, SeekFrom};
use std::sync::{Condvar, Mutex, PoisonError};

/// Largest image [`Gray8Png::decode`] decodes, bytes (= pixels): 64 MiB, 24
/// times a Boreas scan after its 2021 radar upgrade (400 x 6859).
pub const MAX_GRAY8_BYTES: usize = 64 << 20;

/// Memory the `png` crate may spend on the chunks before the image data
/// (text, ICC profiles), bytes.
const MAX_METADATA_BYTES: usize = 8 << 20;

/// Bytes of image data read from a file at a time while inflating.
const READ_PIECE_BYTES: usize = 64 << 10;

/// Where a PNG's bytes are: in memory, or in a file read piece by piece, so
/// decoding a file never holds the whole file beside the image.
#[derive(Clone, Copy)]
enum Source<'a> {
    Bytes(&'a [u8]),
    File(&'a File),
}

impl<'a> Source<'a> {
    /// A reader from the first byte (a file handle is shared: rewound here).
    fn reader(self) -> std::io::Result<Input<'a>> {
        Ok(match self {
            Self::Bytes(bytes) => Input::Bytes(Cursor::new(bytes)),
            Self::File(mut file) => {
                file.seek(SeekFrom::Start(0))?;
                Input::File(BufReader::with_capacity(READ_PIECE_BYTES, file))
            }
        })
    }
}

/// A reader of a [`Source`].
enum Input<'a> {
    Bytes(Cursor<&'a [u8]>),
    File(BufReader<&'a File>),
}

impl Read for Input<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self {
            Self::Bytes(r) => r.read(buf),
            Self::File(r) => r.read(buf),
        }
    }
}

impl BufRead for Input<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        match self {
            Self::Bytes(r) => r.fill_buf(),
            Self::File(r) => r.fill_buf(),
        }
    }

    fn consume(&mut self, amount: usize) {
        match self {
            Self::Bytes(r) => r.consume(amount),
            Self::File(r) => r.consume(amount),
        }
    }
}

impl Seek for Input<'_> {
    fn seek(&mut self, position: SeekFrom) -> std::io::Result<u64> {
        match self {
            Self::Bytes(r) => r.seek(position),
            Self::File(r) => r.seek(position),
        }
    }

    /// Within the buffer, a file's position moves without a read.
    fn seek_relative(&mut self, offset: i64) -> std::io::Result<()> {
        match self {
            Self::Bytes(r) => r.seek_relative(offset),
            Self::File(r) => r.seek_relative(offset),
        }
    }
}

/// An 8-bit greyscale PNG whose header has been read, not yet decoded.
pub struct Gray8Png<'a> {
    source: Source<'a>,
    reader: png::Reader<Input<'a>>,
    width: usize,
    height: usize,
}

impl<'a> Gray8Png<'a> {
    /// Reads the header and the chunks before the image data, allocating
    /// nothing in proportion to the image size. Errors name the problem: not
    /// a PNG, a bad chunk, or a colour type, bit depth or interlacing other
    /// than plain 8-bit grey.
    pub fn open(bytes: &'a [u8]) -> Result<Self, String> {
        Self::open_source(Source::Bytes(bytes))
    }

    /// [`Gray8Png::open`] on a file, which is read piece by piece (here and
    /// by [`Gray8Png::decode`]), never whole: decoding it holds the image and
    /// buffers of [`READ_PIECE_BYTES`], not the file.
    pub fn open_file(file: &'a File) -> Result<Self, String> {
        Self::open_source(Source::File(file))
    }

    fn open_source(source: Source<'a>) -> Result<Self, String> {
        let input = source.reader().map_err(|e| format!("cannot read the PNG: {e}"))?;
        let decoder = png::Decoder::new_with_limits(input, png::Limits { bytes: MAX_METADATA_BYTES });
        let reader = decoder.read_info().map_err(|e| format!("not a readable PNG: {e}"))?;
        let info = reader.info();
        if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Eight {
            return Err(format!(
                "PNG is {:?} with {}-bit samples, expected 8-bit greyscale",
                info.color_type, info.bit_depth as u8
            ));
        }
        if info.interlaced {
            return Err("PNG is interlaced (Adam7); expected a plain, non-interlaced image".into());
        }
        let (width, height) = (info.width as usize, info.height as usize);
        Ok(Self { source, reader, width, height })
    }

    /// Image width from the header, pixels.
    #[must_use]
    pub fn width(&self) -> usize {
        self.width
    }

    /// Image height from the header, rows.
    #[must_use]
    pub fn height(&self) -> usize {
        self.height
    }

    /// Decodes the row-major pixels. Fails on an image over
    /// [`MAX_GRAY8_BYTES`], a bad chunk CRC, a zlib stream that is corrupt,
    /// ends early, runs past the last row or fails its Adler-32 checksum, and a
    /// row with an unknown filter type.
    pub fn decode(mut self) -> Result<Vec<u8>, String> {
        let (width, height) = (self.width, self.height);
        let pixels = width.checked_mul(height).filter(|&n| n <= MAX_GRAY8_BYTES).ok_or_else(|| {
            format!("{width} x {height} pixels is over the {} MiB this reader decodes", MAX_GRAY8_BYTES >> 20)
        })?;
        // Every chunk, image data included, up to IEND: structure and CRCs
        // (the image data is skipped, not inflated).
        self.reader.finish().map_err(|e| format!("PNG data is truncated or corrupt: {e}"))?;
        let _share = DecodeShare::acquire(pixels + height);
        let mut filtered = vec![0u8; pixels + height];
        let mut image_data = ImageData::new(self.source.reader().map_err(|e| format!("cannot read the PNG: {e}"))?);
        inflate_exact(&mut image_data, &mut filtered)
            .map_err(|e| format!("PNG image data ({width} x {height}) is corrupt: {e}"))?;
        unfilter(filtered, width)
    }
}

/// Decodes an 8-bit greyscale PNG into `(width, height, row-major pixels)`;
/// [`Gray8Png`] to check the size before decoding.
pub fn decode_gray8(bytes: &[u8]) -> Result<(usize, usize, Vec<u8>), String> {
    let image = Gray8Png::open(bytes)?;
    let (width, height) = (image.width(), image.height());
    Ok((width, height, image.decode()?))
}

/// The data of the first run of consecutive IDAT chunks, in order, read
/// piece by piece (at most [`READ_PIECE_BYTES`] at a time). The chunk
/// structure and CRCs have been checked by the `png` crate; a chunk header
/// that cannot be read ends the run.
struct ImageData<'a> {
    input: Input<'a>,
    /// Bytes of the current IDAT chunk not yet read.
    left_in_chunk: u64,
    /// Whether the run of IDAT chunks has begun, and whether it has ended.
    started: bool,
    ended: bool,
    /// Whether the input is past the PNG signature (it starts at byte 0).
    after_signature: bool,
    /// Image-data bytes read so far.
    read: u64,
    piece: Vec<u8>,
}

impl<'a> ImageData<'a> {
    fn new(input: Input<'a>) -> Self {
        Self {
            input,
            left_in_chunk: 0,
            started: false,
            ended: false,
            after_signature: false,
            read: 0,
            piece: Vec::new(),
        }
    }

    /// The next piece of image data, and whether it is the last.
    fn next_piece(&mut self) -> std::io::Result<Option<(&[u8], bool)>> {
        if self.piece.is_empty() {
            self.piece = vec![0; READ_PIECE_BYTES];
        }
        while !self.ended && self.left_in_chunk == 0 {
            self.ended = !self.next_chunk()?;
        }
        if self.ended {
            return Ok(None);
        }
        let n = usize::try_from(self.left_in_chunk).map_or(READ_PIECE_BYTES, |left| left.min(READ_PIECE_BYTES));
        self.input.read_exact(&mut self.piece[..n])?;
        self.left_in_chunk -= n as u64;
        self.read += n as u64;
        let mut last = false;
        while !self.ended && self.left_in_chunk == 0 {
            self.ended = !self.next_chunk()?;
            last = self.ended;
        }
        Ok(Some((&self.piece[..n], last)))
    }

    /// Moves to the data of the next IDAT chunk of the run (skipping the
    /// chunks before the run and the current chunk's CRC); false at the end
    /// of the run.
    fn next_chunk(&mut self) -> std::io::Result<bool> {
        if self.started {
            self.input.seek_relative(4)?; // the CRC
        } else if !self.after_signature {
            self.input.seek_relative(8)?;
            self.after_signature = true;
        }
        loop {
            let mut header = [0u8; 8];
            if self.input.read_exact(&mut header).is_err() {
                return Ok(false);
            }
            let length = u64::from(u32::from_be_bytes([header[0], header[1], header[2], header[3]]));
            if &header[4..8] == b"IDAT" {
                self.started = true;
                self.left_in_chunk = length;
                return Ok(true);
            }
            if self.started {
                return Ok(false);
            }
            self.input.seek_relative(i64::try_from(length + 4).unwrap_or(i64::MAX))?;
        }
    }

    /// Bytes of image data in the run not yet read (skipped, not read).
    fn skip_rest(&mut self) -> std::io::Result<u64> {
        let mut rest = 0;
        while !self.ended {
            rest += self.left_in_chunk;
            self.input.seek_relative(i64::try_from(self.left_in_chunk).unwrap_or(i64::MAX))?;
            self.left_in_chunk = 0;
            self.ended = !self.next_chunk()?;
        }
        Ok(rest)
    }
}

/// Inflates the zlib stream of `image_data` into `out`, which it must fill
/// exactly; the stream's Adler-32 is verified, and no byte may follow it in
/// the image data.
///
/// `fdeflate` reads up to 7 bytes ahead of what it decodes, so whether the
/// stream ends at the last byte cannot be told from what it consumed: the
/// checksum is verified here instead, and its position among the last
/// bytes consumed is where the stream ends.
fn inflate_exact(image_data: &mut ImageData<'_>, out: &mut [u8]) -> Result<(), String> {
    let io_error = |e: std::io::Error| format!("cannot read the image data: {e}");
    let mut inflater = fdeflate::Decompressor::new();
    inflater.ignore_adler32();
    let (mut filled, mut consumed_total) = (0, 0u64);
    // The last bytes consumed, newest last: where the checksum is.
    let mut tail = [0u8; 16];
    while let Some((piece, last)) = image_data.next_piece().map_err(io_error)? {
        let mut input = piece;
        while !input.is_empty() && !inflater.is_done() {
            let (consumed, produced) =
                inflater.read(input, out, filled, last).map_err(|e| inflate_error(&e, filled, out.len()))?;
            if consumed == 0 && produced == 0 {
                return Err(format!("the zlib stream holds more than the {} bytes of the pixel rows", out.len()));
            }
            let kept = consumed.min(tail.len());
            tail.copy_within(kept.., 0);
            let start = tail.len() - kept;
            tail[start..].copy_from_slice(&input[consumed - kept..consumed]);
            input = &input[consumed..];
            filled += produced;
            consumed_total += consumed as u64;
        }
        if inflater.is_done() {
            break;
        }
    }
    if !inflater.is_done() {
        return Err(format!(
            "the zlib stream ends after {filled} of {} bytes, before its Adler-32 checksum",
            out.len()
        ));
    }
    if filled != out.len() {
        return Err(format!("the zlib stream holds {filled} bytes, expected {} for the pixel rows", out.len()));
    }
    let mut adler = simd_adler32::Adler32::new();
    adler.write(out);
    let trailer = adler.finish().to_be_bytes();
    // The byte at offset `at` of the image data, if among the tail.
    let byte = |at: u64| {
        let back = consumed_total.checked_sub(at)?;
        (1..=tail.len() as u64).contains(&back).then(|| tail[tail.len() - back as usize])
    };
    let stream_end = (0..8)
        .filter_map(|ahead| consumed_total.checked_sub(ahead).filter(|&end| end >= 4))
        .find(|&end| (0..4).all(|j| byte(end - 4 + j) == Some(trailer[j as usize])))
        .ok_or("the zlib stream's Adler-32 checksum does not match its data")?;
    let after = image_data.read + image_data.skip_rest().map_err(io_error)? - stream_end;
    if after > 0 {
        return Err(format!(
            "{after} bytes follow the end of the zlib stream (its Adler-32 checksum) in the image data"
        ));
    }
    Ok(())
}

fn inflate_error(error: &fdeflate::DecompressionError, filled: usize, expected: usize) -> String {
    match error {
        fdeflate::DecompressionError::WrongChecksum => {
            "the zlib stream's Adler-32 checksum does not match its data".to_string()
        }
        fdeflate::DecompressionError::InsufficientInput => {
            format!("the zlib stream ends after {filled} of {expected} bytes")
        }
        other => format!("invalid zlib stream after {filled} bytes ({other:?})"),
    }
}

/// Undoes the PNG row filters of 8-bit, one-channel rows (`width + 1` bytes
/// each: the filter type, then the filtered pixels), in place: each row
/// moves one byte per row above it to the left, onto the end of the rows
/// already done, so no second image-sized buffer is needed.
///
/// # References
/// PNG specification (W3C, 3rd ed.), section 7.3 "Filtering" and 9.4 "Filter
/// types" (Sub, Up, Average, Paeth with one byte per pixel).
fn unfilter(mut data: Vec<u8>, width: usize) -> Result<Vec<u8>, String> {
    let rows = data.len() / (width + 1);
    let zeros = vec![0u8; width];
    for row in 0..rows {
        let (from, to) = (row * (width + 1), row * width);
        let kind = data[from];
        data.copy_within(from + 1..from + 1 + width, to);
        let (done, rest) = data.split_at_mut(to);
        let above = if row == 0 { &zeros[..] } else { &done[to - width..] };
        let out = &mut rest[..width];
        match kind {
            0 => {}
            1 => {
                let mut left = 0u8;
                for o in out.iter_mut() {
                    left = o.wrapping_add(left);
                    *o = left;
                }
            }
            2 => {
                for (o, &b) in out.iter_mut().zip(above) {
                    *o = o.wrapping_add(b);
                }
            }
            3 => {
                let mut left = 0u8;
                for (o, &b) in out.iter_mut().zip(above) {
                    left = o.wrapping_add(((u16::from(left) + u16::from(b)) / 2) as u8);
                    *o = left;
                }
            }
            4 => {
                let (mut left, mut upper_left) = (0u8, 0u8);
                for (o, &b) in out.iter_mut().zip(above) {
                    left = o.wrapping_add(paeth(left, b, upper_left));
                    upper_left = b;
                    *o = left;
                }
            }
            other => return Err(format!("PNG row {row}: filter type {other}, expected 0-4")),
        }
    }
    data.truncate(rows * width);
    Ok(data)
}

/// Bytes of image data the decodes running at once may hold: one image at
/// [`MAX_GRAY8_BYTES`]. Real scans (a few MB) decode side by side on every
/// thread; images near the cap decode one at a time, so a folder of PNG
/// bombs costs one cap-sized buffer whatever the thread count.
const DECODE_BUDGET_BYTES: usize = MAX_GRAY8_BYTES;

/// Bytes held by the decodes running now, and the signal that some were
/// released.
static DECODES_IN_USE: Mutex<usize> = Mutex::new(0);
static DECODE_RELEASED: Condvar = Condvar::new();

/// A running decode's share of [`DECODE_BUDGET_BYTES`], given back on drop.
struct DecodeShare(usize);

impl DecodeShare {
    /// Waits until `bytes` fit in the budget beside the decodes running, or
    /// none is running (a decode alone always starts: it is under the cap).
    fn acquire(bytes: usize) -> Self {
        let mut in_use = DECODES_IN_USE.lock().unwrap_or_else(PoisonError::into_inner);
        while *in_use > 0 && in_use.saturating_add(bytes) > DECODE_BUDGET_BYTES {
            in_use = DECODE_RELEASED.wait(in_use).unwrap_or_else(PoisonError::into_inner);
        }
        *in_use += bytes;
        Self(bytes)
    }
}

impl Drop for DecodeShare {
    fn drop(&mut self) {
        let mut in_use = DECODES_IN_USE.lock().unwrap_or_else(PoisonError::into_inner);
        *in_use -= self.0;
        DECODE_RELEASED.notify_all();
    }
}

/// The Paeth predictor: of left `a`, above `b` and upper-left `c`, the one
/// closest to `a + b - c` (ties in that order).
fn paeth(a: u8, b: u8, c: u8) -> u8 {
    let p = i16::from(a) + i16::from(b) - i16::from(c);
    let (pa, pb, pc) = ((p - i16::from(a)).abs(), (p - i16::from(b)).abs(), (p - i16::from(c)).abs());
    if pa <= pb && pa <= pc {
        a
    } else if pb <= pc {
        b
    } else {
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The data of the first run of consecutive IDAT chunks, in order.
    fn image_data(png: &[u8]) -> Vec<&[u8]> {
        let mut chunks = Vec::new();
        let mut at = 8; // after the signature
        while let Some(header) = png.get(at..at + 8) {
            let length = u32::from_be_bytes([header[0], header[1], header[2], header[3]]) as usize;
            let Some(data) = png.get(at + 8..).and_then(|rest| rest.get(..length)) else { break };
            if &header[4..8] == b"IDAT" {
                chunks.push(data);
            } else if !chunks.is_empty() {
                break;
            }
            at += 12 + length;
        }
        chunks
    }

    fn encode(width: u32, height: u32, pixels: &[u8], filter: png::Filter, compression: png::Compression) -> Vec<u8> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, width, height);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_filter(filter);
        encoder.set_compression(compression);
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(pixels).unwrap();
        writer.finish().unwrap();
        out
    }

    /// A PNG with the given header and `idat` as its one IDAT chunk, every
    /// CRC correct (the `png` writer computes them).
    fn repack(width: u32, height: u32, idat: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, width, height);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().unwrap();
        writer.write_chunk(png::chunk::IDAT, idat).unwrap();
        drop(writer); // writes IEND
        out
    }

    /// The `png` crate's own full-frame decode: the reference, and the
    /// decoder this module replaced.
    fn png_crate_decode(bytes: &[u8]) -> Result<Vec<u8>, String> {
        let mut reader = png::Decoder::new(Cursor::new(bytes)).read_info().map_err(|e| e.to_string())?;
        let mut pixels = vec![0; reader.output_buffer_size().ok_or("size")?];
        reader.next_frame(&mut pixels).map_err(|e| e.to_string())?;
        Ok(pixels)
    }

    fn noise(n: usize, seed: u64) -> Vec<u8> {
        let mut state = seed | 1;
        (0..n)
            .map(|i| {
                state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                // Smooth ramps with sparse noise, so every filter type gets chosen.
                ((i % 97) as u8).wrapping_add(((state >> 61) as u8) * u8::from(i % 5 == 0))
            })
            .collect()
    }

    #[test]
    fn every_filter_type_decodes_as_the_png_crate_does() {
        let (width, height) = (37, 23);
        let pixels = noise(width * height, 7);
        for filter in [
            png::Filter::NoFilter,
            png::Filter::Sub,
            png::Filter::Up,
            png::Filter::Avg,
            png::Filter::Paeth,
            png::Filter::Adaptive,
        ] {
            for compression in [png::Compression::NoCompression, png::Compression::Fast, png::Compression::High] {
                let bytes = encode(width as u32, height as u32, &pixels, filter, compression);
                assert_eq!(decode_gray8(&bytes).unwrap(), (width, height, pixels.clone()), "{filter:?}");
                assert_eq!(png_crate_decode(&bytes).unwrap(), pixels);
            }
        }
    }

    /// One bit flipped in the image data, the chunk CRC made right again:
    /// only the zlib stream's own checks can tell. The `png` crate's decoder
    /// returned altered pixels without an error for many of these flips
    /// (every flip of an uncompressed stream, a few near the end of a
    /// compressed one). Here each is an error, or the true pixels (the flip
    /// hit bits the stream ignores), or, rarely, a change Adler-32 cannot see
    /// (a flipped back-reference that permutes bytes so that both of its
    /// sums are unchanged).
    #[test]
    fn image_data_corrupted_under_a_good_crc_is_refused() {
        let (width, height) = (301u32, 40u32);
        let pixels = noise((width * height) as usize, 3);
        let (mut slipped_past_png_crate, mut adler_collisions, mut refused) = (0, 0, 0);
        for compression in [png::Compression::NoCompression, png::Compression::Fast, png::Compression::Balanced] {
            let good = encode(width, height, &pixels, png::Filter::Adaptive, compression);
            let idat: Vec<u8> = image_data(&good).concat();
            let true_stream = fdeflate::decompress_to_vec(&idat).unwrap();
            // Every byte of the last 64 and 200 spread over the rest.
            let positions = (0..idat.len()).filter(|i| i % (idat.len() / 200) == 0 || idat.len() - i <= 64);
            for position in positions {
                let mut flipped = idat.clone();
                flipped[position] ^= 0x10;
                let bad = repack(width, height, &flipped);
                if png_crate_decode(&bad).is_ok_and(|p| p != pixels) {
                    slipped_past_png_crate += 1;
                }
                match decode_gray8(&bad) {
                    Err(e) => {
                        assert!(e.contains("corrupt"), "{e}");
                        refused += 1;
                    }
                    Ok((_, _, decoded)) if decoded == pixels => {}
                    Ok(_) => {
                        let mut inflater = fdeflate::Decompressor::new();
                        inflater.ignore_adler32();
                        let mut stream = vec![0; true_stream.len()];
                        inflater.read(&flipped, &mut stream, 0, true).unwrap();
                        assert_eq!(
                            adler2::adler32_slice(&stream),
                            adler2::adler32_slice(&true_stream),
                            "{compression:?}, byte {position}"
                        );
                        adler_collisions += 1;
                    }
                }
            }
        }
        assert!(slipped_past_png_crate > 200, "the png crate missed {slipped_past_png_crate} corruptions");
        assert!(adler_collisions <= 2 && refused > 500, "{adler_collisions} collisions, {refused} refused");
        let good = encode(width, height, &pixels, png::Filter::Adaptive, png::Compression::NoCompression);
        let mut idat = image_data(&good).concat();
        let middle = idat.len() / 2;
        idat[middle] ^= 1;
        let err = decode_gray8(&repack(width, height, &idat)).unwrap_err();
        assert!(err.contains("Adler-32") && err.contains("301 x 40"), "{err}");
    }

    #[test]
    fn stream_longer_or_shorter_than_the_header_says_is_refused() {
        let pixels = noise(30 * 6, 5);
        let idat = image_data(&encode(30, 6, &pixels, png::Filter::Sub, png::Compression::Fast)).concat();
        let err = decode_gray8(&repack(30, 5, &idat)).unwrap_err();
        assert!(err.contains("more than the 155 bytes"), "{err}");
        let err = decode_gray8(&repack(30, 7, &idat)).unwrap_err();
        assert!(err.contains("holds 186 bytes, expected 217"), "{err}");
        // The png crate took the longer stream: it stops at the last row.
        assert!(png_crate_decode(&repack(30, 5, &idat)).is_ok());
    }

    /// Before: 64 junk bytes after the zlib stream's end inside IDAT were
    /// accepted, though the stream must end exactly after the last row.
    #[test]
    fn bytes_after_the_end_of_the_zlib_stream_are_refused() {
        let pixels = noise(30 * 6, 5);
        let idat = image_data(&encode(30, 6, &pixels, png::Filter::Sub, png::Compression::Fast)).concat();
        assert_eq!(decode_gray8(&repack(30, 6, &idat)).unwrap().2, pixels);
        // Counted exactly, also under the 7 bytes fdeflate reads ahead.
        for n in [1, 2, 3, 7, 8, 64] {
            let mut junk = idat.clone();
            junk.extend(std::iter::repeat_n(0xAB, n));
            let err = decode_gray8(&repack(30, 6, &junk)).unwrap_err();
            assert!(err.contains(&format!(": {n} bytes follow the end of the zlib stream")), "{n}: {err}");
        }
        // The same junk in an IDAT chunk of its own after the stream.
        let mut two = Vec::new();
        let mut encoder = png::Encoder::new(&mut two, 30, 6);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().unwrap();
        writer.write_chunk(png::chunk::IDAT, &idat).unwrap();
        writer.write_chunk(png::chunk::IDAT, &[0xAB; 64]).unwrap();
        drop(writer);
        let err = decode_gray8(&two).unwrap_err();
        assert!(err.contains("64 bytes follow the end of the zlib stream"), "{err}");
    }

    fn decode_file(bytes: &[u8]) -> Result<Vec<u8>, String> {
        let mut file = tempfile::tempfile().unwrap();
        std::io::Write::write_all(&mut file, bytes).unwrap();
        Gray8Png::open_file(&file)?.decode()
    }

    /// A file is read in pieces of 64 KiB: images whose data spans many
    /// pieces and chunks (stored, so every byte is data), and the errors of
    /// a bad stream, are the same as from memory.
    #[test]
    fn a_file_read_in_pieces_decodes_as_from_memory() {
        let (width, height) = (1001u32, 300u32);
        let pixels = noise((width * height) as usize, 11);
        for (stored, compression) in [(true, png::Compression::NoCompression), (false, png::Compression::Fast)] {
            let bytes = encode(width, height, &pixels, png::Filter::Paeth, compression);
            assert!(!stored || bytes.len() > 4 * READ_PIECE_BYTES, "{} bytes", bytes.len());
            assert_eq!(decode_file(&bytes).unwrap(), pixels);
            // The same data as many small chunks, one of them empty.
            let idat = image_data(&bytes).concat();
            let mut split = Vec::new();
            let mut encoder = png::Encoder::new(&mut split, width, height);
            encoder.set_color(png::ColorType::Grayscale);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header().unwrap();
            for (i, part) in idat.chunks(7777).enumerate() {
                writer.write_chunk(png::chunk::IDAT, part).unwrap();
                if i == 3 {
                    writer.write_chunk(png::chunk::IDAT, &[]).unwrap();
                }
            }
            drop(writer);
            assert_eq!(decode_file(&split).unwrap(), pixels);
            for n in [1, 7, 8, 100_000] {
                let mut junk = idat.clone();
                junk.extend(std::iter::repeat_n(0xAB, n));
                let bad = repack(width, height, &junk);
                let err = decode_file(&bad).unwrap_err();
                assert_eq!(err, decode_gray8(&bad).unwrap_err());
                assert!(err.contains(&format!(": {n} bytes follow the end of the zlib stream")), "{n}: {err}");
            }
            let short = repack(width, height, &idat[..idat.len() - 10]);
            assert_eq!(decode_file(&short).unwrap_err(), decode_gray8(&short).unwrap_err());
        }
    }

    #[test]
    fn huge_header_is_read_without_allocating_and_refused_on_decode() {
        let idat = image_data(&encode(1, 1, &[0], png::Filter::NoFilter, png::Compression::Fast)).concat();
        let bytes = repack(100_000, 100_000, &idat);
        assert!(bytes.len() < 100, "{} bytes", bytes.len());
        let image = Gray8Png::open(&bytes).unwrap();
        assert_eq!((image.width(), image.height()), (100_000, 100_000));
        let err = image.decode().unwrap_err();
        assert!(err.contains("100000 x 100000") && err.contains("64 MiB"), "{err}");
    }

    #[test]
    fn wrong_kinds_of_png_are_named() {
        let mut sixteen = Vec::new();
        let mut encoder = png::Encoder::new(&mut sixteen, 2, 2);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Sixteen);
        encoder.write_header().unwrap().write_image_data(&[0; 8]).unwrap();
        let err = decode_gray8(&sixteen).err().unwrap();
        assert!(err.contains("16-bit") && err.contains("8-bit greyscale"), "{err}");

        // Filter type 7 on the second row.
        let raw = [0u8, 1, 2, 7, 3, 4];
        let err = decode_gray8(&repack(2, 2, &fdeflate::compress_to_vec(&raw))).unwrap_err();
        assert!(err.contains("row 1") && err.contains("filter type 7"), "{err}");

        let good = encode(4, 4, &[9; 16], png::Filter::NoFilter, png::Compression::Fast);
        let err = decode_gray8(&good[..good.len() - 12]).unwrap_err();
        assert!(err.contains("truncated or corrupt"), "no IEND: {err}");
        let err = decode_gray8(b"GIF89a").err().unwrap();
        assert!(err.contains("not a readable PNG"), "{err}");
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]
        /// Any image, any filter: the same pixels as the png crate; cut or
        /// arbitrary bytes are an error, never a panic.
        #[test]
        fn decodes_like_the_png_crate_and_never_panics(
            width in 1u32..40, height in 1u32..12, seed in any::<u64>(), filter in 0usize..6,
            cut in 0usize..2000, junk in proptest::collection::vec(any::<u8>(), 0..200),
        ) {
            let filters = [png::Filter::NoFilter, png::Filter::Sub, png::Filter::Up, png::Filter::Avg, png::Filter::Paeth, png::Filter::Adaptive];
            let pixels = noise((width * height) as usize, seed);
            let bytes = encode(width, height, &pixels, filters[filter], png::Compression::Fast);
            prop_assert_eq!(decode_gray8(&bytes).unwrap().2, pixels);
            let _ = decode_gray8(&bytes[..cut.min(bytes.len())]);
            let _ = decode_gray8(&junk);
            let mut spliced = bytes[..33.min(bytes.len())].to_vec();
            spliced.extend_from_slice(&junk);
            let _ = decode_gray8(&spliced);
        }
    }
}
