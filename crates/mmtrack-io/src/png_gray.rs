//! Decoding of 8-bit greyscale PNGs (Navtech polar scans), with errors that say
//! what was wrong with the image rather than panicking.

/// Decodes an 8-bit greyscale PNG into `(width, height, row-major pixels)`.
///
/// Errors name the problem: not a PNG, truncated data, or a colour type/bit
/// depth other than 8-bit grey.
pub fn decode_gray8(bytes: &[u8]) -> Result<(usize, usize, Vec<u8>), String> {
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = decoder.read_info().map_err(|e| format!("not a readable PNG: {e}"))?;
    let info = reader.info();
    if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Eight {
        return Err(format!(
            "PNG is {:?} with {}-bit samples, expected 8-bit greyscale",
            info.color_type, info.bit_depth as u8
        ));
    }
    let (width, height) = (info.width as usize, info.height as usize);
    let size = reader.output_buffer_size().ok_or("PNG dimensions overflow memory")?;
    let mut pixels = vec![0; size];
    let frame = reader.next_frame(&mut pixels).map_err(|e| format!("PNG data is truncated or corrupt: {e}"))?;
    pixels.truncate(frame.buffer_size());
    if pixels.len() != width * height {
        return Err(format!("PNG holds {} bytes, expected {width} x {height}", pixels.len()));
    }
    Ok((width, height, pixels))
}
