//! A bounds-checked reader of ROS 2 CDR messages.
//!
//! CDR (OMG XCDR1, as ROS 2's rmw implementations write it): a 4-byte
//! encapsulation header (`00 01` little-endian, `00 00` big-endian, then two
//! option bytes; both byte orders are decoded), then the fields in declaration order, each primitive aligned
//! to its own size counted from the end of the encapsulation header; strings
//! are a `uint32` length including the terminating NUL, then the bytes. Other
//! encapsulations (parameter lists `00 02`/`00 03`, XCDR2 `00 06`..`00 0b`)
//! are refused by name. A string or sequence length larger than the message,
//! or a stamp's nanoseconds of a second or more, that would fit once
//! byte-swapped is reported as a payload in the other byte order than its
//! header says. The
//! ROS 2 readers ([`crate::ros2`], [`crate::ros2_image`]) decode by hand with
//! it: the few fixed message layouts they need do not justify a general IDL
//! machinery, and every read is bounds-checked so a truncated or corrupted
//! message is an error naming the field, never a panic.

/// A bounds-checked CDR reader over one message.
pub struct Cdr<'a> {
    body: &'a [u8],
    position: usize,
    little_endian: bool,
}

impl<'a> Cdr<'a> {
    /// Starts after the encapsulation header.
    pub fn new(data: &'a [u8]) -> Result<Self, String> {
        let header = data.get(..4).ok_or("shorter than the 4-byte CDR encapsulation header")?;
        let little_endian = match header[..2] {
            [0x00, 0x01] => true,
            [0x00, 0x00] => false,
            [0x00, 0x02 | 0x03] => {
                return Err(format!(
                    "CDR encapsulation {:02x}{:02x} is a parameter list (PL_CDR), not supported: expected plain CDR, \
                     00 01 (little-endian) or 00 00 (big-endian)",
                    header[0], header[1]
                ));
            }
            [0x00, 0x06..=0x0b] => {
                return Err(format!(
                    "CDR encapsulation {:02x}{:02x} is XCDR2, not supported: expected plain CDR (XCDR1), \
                     00 01 (little-endian) or 00 00 (big-endian)",
                    header[0], header[1]
                ));
            }
            _ => {
                return Err(format!(
                    "unknown CDR encapsulation {:02x}{:02x}: expected 00 01 (little-endian) or 00 00 (big-endian)",
                    header[0], header[1]
                ));
            }
        };
        Ok(Self { body: &data[4..], position: 0, little_endian })
    }

    fn take(&mut self, field: &str, size: usize, align: usize) -> Result<&'a [u8], String> {
        let start = self.position.next_multiple_of(align);
        let end = start.checked_add(size).ok_or_else(|| format!("{field}: length overflows"))?;
        let bytes = self
            .body
            .get(start..end)
            .ok_or_else(|| format!("{field}: message ends at byte {} but the field needs {end}", self.body.len()))?;
        self.position = end;
        Ok(bytes)
    }

    fn array<const N: usize>(&mut self, field: &str) -> Result<[u8; N], String> {
        let mut out = [0u8; N];
        out.copy_from_slice(self.take(field, N, N)?);
        if !self.little_endian {
            out.reverse();
        }
        Ok(out)
    }

    /// A `uint8`.
    pub fn u8(&mut self, field: &str) -> Result<u8, String> {
        Ok(self.take(field, 1, 1)?[0])
    }

    /// A `uint16`.
    pub fn u16(&mut self, field: &str) -> Result<u16, String> {
        Ok(u16::from_le_bytes(self.array(field)?))
    }

    /// A `uint32`.
    pub fn u32(&mut self, field: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.array(field)?))
    }

    /// An `int32`.
    pub fn i32(&mut self, field: &str) -> Result<i32, String> {
        Ok(i32::from_le_bytes(self.array(field)?))
    }

    /// A `float64`.
    pub fn f64(&mut self, field: &str) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.array(field)?))
    }

    /// The `uint32` length of a string or sequence, checked against the
    /// bytes left: a length that does not fit but would once byte-swapped
    /// means the payload is in the other byte order than the header says.
    fn length(&mut self, field: &str) -> Result<usize, String> {
        let len = self.u32(field)?;
        let left = self.body.len().saturating_sub(self.position);
        if len as usize > left && (len.swap_bytes() as usize) <= left {
            return Err(self.wrong_byte_order(field, &format!("length {len} is more than the {left} bytes left"), len));
        }
        Ok(len as usize)
    }

    /// The message for a `uint32` field whose value is impossible as read
    /// (`problem`) but plausible byte-swapped.
    fn wrong_byte_order(&self, field: &str, problem: &str, value: u32) -> String {
        let (said, looks) = if self.little_endian { ("little", "big") } else { ("big", "little") };
        format!(
            "{field}: {problem}, but {} read {looks}-endian: the encapsulation header says {said}-endian and the \
             payload looks {looks}-endian",
            value.swap_bytes()
        )
    }

    /// A `string`.
    pub fn string(&mut self, field: &str) -> Result<String, String> {
        let len = self.length(field)?;
        let bytes = self.take(field, len, 1)?;
        let text = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        String::from_utf8(text.to_vec()).map_err(|_| format!("{field}: not UTF-8"))
    }

    /// A `sequence<uint8>` (a `uint32` count, then the bytes), borrowed.
    pub fn byte_sequence(&mut self, field: &str) -> Result<&'a [u8], String> {
        let len = self.length(field)?;
        self.take(field, len, 1)
    }

    /// A `builtin_interfaces/Time`, as nanoseconds.
    pub fn stamp_ns(&mut self, field: &str) -> Result<i64, String> {
        let sec = self.i32(field)?;
        let nanosec = self.u32(field)?;
        if nanosec >= 1_000_000_000 {
            let problem = format!("nanosec {nanosec} is not below one second");
            if nanosec.swap_bytes() < 1_000_000_000 {
                return Err(self.wrong_byte_order(field, &problem, nanosec));
            }
            return Err(format!("{field}: {problem}"));
        }
        Ok(i64::from(sec) * 1_000_000_000 + i64::from(nanosec))
    }
}
