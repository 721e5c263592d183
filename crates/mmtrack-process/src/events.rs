//! Reading a recording as a stream of events, with radar scans decoded in
//! parallel ahead of the consumer.

use std::collections::BTreeMap;
use std::path::Path;

use mmtrack_io::recording::RecordingItem;
use mmtrack_io::{RecordingEvent, RecordingReader};

/// Scans decoded ahead of `f`, per thread of the pool.
const SCANS_PER_THREAD: usize = 2;

/// Calls `f` with every event of the recording in file order (and the bytes
/// read so far). Radar scans are decoded on the current rayon pool, a few per
/// thread ahead of `f` ([`mmtrack_core::parallel::map_in_order`]), so
/// reading, PNG inflating and `f` overlap, order is kept and memory holds a
/// bounded number of scans. Reading stops at the first bad record. Returns the
/// recording metadata.
///
/// # Errors
/// The first bad record, or the first error of `f`.
pub fn for_each_event(
    recording: &Path,
    mut f: impl FnMut(RecordingEvent, u64) -> anyhow::Result<()> + Send,
) -> anyhow::Result<Option<BTreeMap<String, String>>> {
    let mut reader = RecordingReader::open(recording)?;
    let mut failed = false;
    let items = std::iter::from_fn(|| {
        if failed {
            return None;
        }
        let item = reader.next_item()?;
        failed = item.is_err();
        Some((item, reader.bytes_read()))
    });
    mmtrack_core::parallel::map_in_order(
        items,
        SCANS_PER_THREAD,
        |(item, bytes_read)| {
            let event = match item {
                Ok(RecordingItem::Event(event)) => Ok(event),
                Ok(RecordingItem::Scan(scan)) => scan.decode().map(RecordingEvent::RadarScan),
                Err(e) => Err(e),
            };
            (event, bytes_read)
        },
        |(event, bytes_read)| f(event?, bytes_read),
    )?;
    Ok(reader.metadata().cloned())
}
