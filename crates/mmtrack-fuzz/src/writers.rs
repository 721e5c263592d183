//! Small writers of the formats under test, for seeds: valid inputs the
//! readers accept, so that mutations start from the deep end of each format.
//! Only what the seeds need; none of this is used outside the fuzzer.

/// A CDR (XCDR1, little-endian) message writer: primitives aligned to their
/// size from the end of the 4-byte encapsulation header.
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl Default for CdrWriter {
    fn default() -> Self {
        Self { buf: vec![0, 1, 0, 0] }
    }
}

impl CdrWriter {
    fn align(&mut self, n: usize) {
        while !(self.buf.len() - 4).is_multiple_of(n) {
            self.buf.push(0);
        }
    }

    /// Appends a `uint8`.
    pub fn u8(&mut self, v: u8) -> &mut Self {
        self.buf.push(v);
        self
    }

    /// Appends a `uint16`.
    pub fn u16(&mut self, v: u16) -> &mut Self {
        self.align(2);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// Appends a `uint32`.
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// Appends a `float64`.
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// Appends a string: length with the NUL, bytes, NUL.
    pub fn string(&mut self, s: &str) -> &mut Self {
        self.u32(s.len() as u32 + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
        self
    }

    /// Appends a `sequence<uint8>`.
    pub fn bytes(&mut self, b: &[u8]) -> &mut Self {
        self.u32(b.len() as u32);
        self.buf.extend_from_slice(b);
        self
    }

    /// Appends a `std_msgs/Header` (stamp and frame id).
    pub fn header(&mut self, sec: u32, nanosec: u32, frame_id: &str) -> &mut Self {
        self.u32(sec).u32(nanosec).string(frame_id)
    }

    /// The message.
    #[must_use]
    pub fn finish(&self) -> Vec<u8> {
        self.buf.clone()
    }
}

/// A `.npy` (format version `version`, 1 or 2) with the given dtype, order, shape text and data.
#[must_use]
pub fn npy(version: u8, descr: &str, fortran: bool, shape: &str, data: &[u8]) -> Vec<u8> {
    let order = if fortran { "True" } else { "False" };
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {shape}, }}").into_bytes();
    let prefix = if version == 1 { 10 } else { 12 };
    while !(prefix + header.len() + 1).is_multiple_of(64) {
        header.push(b' ');
    }
    header.push(b'\n');
    let mut out = b"\x93NUMPY".to_vec();
    out.extend_from_slice(&[version, 0]);
    if version == 1 {
        out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    } else {
        out.extend_from_slice(&(header.len() as u32).to_le_bytes());
    }
    out.extend(header);
    out.extend_from_slice(data);
    out
}

/// A raw DEFLATE stream of stored (uncompressed) blocks.
#[must_use]
pub fn deflate_stored(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut chunks = data.chunks(65_535).peekable();
    if chunks.peek().is_none() {
        out.extend_from_slice(&[1, 0, 0, 0xff, 0xff]);
    }
    while let Some(chunk) = chunks.next() {
        out.push(u8::from(chunks.peek().is_none()));
        let len = chunk.len() as u16;
        out.extend_from_slice(&len.to_le_bytes());
        out.extend_from_slice(&(!len).to_le_bytes());
        out.extend_from_slice(chunk);
    }
    out
}

/// A zlib stream of stored blocks, with its Adler-32.
#[must_use]
pub fn zlib_stored(data: &[u8]) -> Vec<u8> {
    let mut out = vec![0x78, 0x01];
    out.extend(deflate_stored(data));
    out.extend_from_slice(&adler2::adler32_slice(data).to_be_bytes());
    out
}

/// A ZIP archive of `(name, data)` members, deflated (as stored DEFLATE
/// blocks) when `deflate`, else stored.
#[must_use]
pub fn zip(members: &[(&str, Vec<u8>)], deflate: bool) -> Vec<u8> {
    let (mut out, mut central) = (Vec::new(), Vec::new());
    for (name, data) in members {
        let offset = out.len() as u32;
        let body = if deflate { deflate_stored(data) } else { data.clone() };
        let fields = |out: &mut Vec<u8>| {
            out.extend_from_slice(&20u16.to_le_bytes()); // version needed
            out.extend_from_slice(&0u16.to_le_bytes()); // flags
            out.extend_from_slice(&(if deflate { 8u16 } else { 0 }).to_le_bytes());
            out.extend_from_slice(&[0; 4]); // time, date
            out.extend_from_slice(&crc32fast::hash(data).to_le_bytes());
            out.extend_from_slice(&(body.len() as u32).to_le_bytes());
            out.extend_from_slice(&(data.len() as u32).to_le_bytes());
            out.extend_from_slice(&(name.len() as u16).to_le_bytes());
            out.extend_from_slice(&0u16.to_le_bytes()); // extra
        };
        out.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        fields(&mut out);
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(&body);
        central.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        central.extend_from_slice(&20u16.to_le_bytes()); // version made by
        fields(&mut central);
        central.extend_from_slice(&[0; 10]); // comment length, disk, internal and external attributes
        central.extend_from_slice(&offset.to_le_bytes());
        central.extend_from_slice(name.as_bytes());
    }
    let directory_at = out.len() as u32;
    out.extend_from_slice(&central);
    out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
    out.extend_from_slice(&[0; 4]);
    out.extend_from_slice(&(members.len() as u16).to_le_bytes());
    out.extend_from_slice(&(members.len() as u16).to_le_bytes());
    out.extend_from_slice(&(central.len() as u32).to_le_bytes());
    out.extend_from_slice(&directory_at.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    out
}

/// One MATLAB v5 data element (8-byte tag), padded to 8 bytes.
fn mat_element(data_type: u32, data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(8 + data.len().next_multiple_of(8));
    out.extend_from_slice(&data_type.to_le_bytes());
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
    out.resize(8 + data.len().next_multiple_of(8), 0);
    out
}

/// A little-endian MATLAB v5 `.mat` file with one double array `name` of
/// `dims` (column-major values), complex when `imag` is given; the variable
/// is zlib-compressed (stored blocks) when `compressed`.
#[must_use]
pub fn mat_v5(name: &str, dims: &[u32], real: &[f64], imag: Option<&[f64]>, compressed: bool) -> Vec<u8> {
    let mut out = b"MATLAB 5.0 MAT-file, written by mmtrack-fuzz".to_vec();
    out.resize(116, b' ');
    out.extend_from_slice(&[0; 8]); // subsystem data offset
    out.extend_from_slice(&0x0100u16.to_le_bytes());
    out.extend_from_slice(b"IM");
    let flags = 6u32 | if imag.is_some() { 0x0800 } else { 0 };
    let mut body = mat_element(6, &[flags.to_le_bytes(), 0u32.to_le_bytes()].concat());
    body.extend(mat_element(5, &dims.iter().flat_map(|d| d.to_le_bytes()).collect::<Vec<_>>()));
    body.extend(mat_element(1, name.as_bytes()));
    let doubles = |v: &[f64]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<_>>();
    body.extend(mat_element(9, &doubles(real)));
    if let Some(imag) = imag {
        body.extend(mat_element(9, &doubles(imag)));
    }
    let matrix = mat_element(14, &body);
    if compressed {
        let stream = zlib_stored(&matrix);
        out.extend_from_slice(&15u32.to_le_bytes());
        out.extend_from_slice(&(stream.len() as u32).to_le_bytes());
        out.extend(stream);
    } else {
        out.extend(matrix);
    }
    out
}

/// An NMEA 0183 sentence (`$`, payload, `*`, checksum, CRLF).
#[must_use]
pub fn nmea_sentence(payload: &str) -> String {
    let checksum = payload.bytes().fold(0u8, |c, b| c ^ b);
    format!("${payload}*{checksum:02X}\r\n")
}
