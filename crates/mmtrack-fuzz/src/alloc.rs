//! The global allocator of every process that links this crate (the fuzz
//! binary and its tests): the system allocator, plus a note of each single
//! request above [`ALLOCATION_CAP_BYTES`], so that a size field a reader
//! trusts becomes a finding instead of an aborted process.
//!
//! An over-cap request is still passed to the system allocator: on Linux a
//! large block is mapped lazily, so asking costs nothing until it is written,
//! and the fuzz loop reports the request after the input ran
//! ([`take_usage`]). The allocator also adds up all requests of an input
//! ([`TOTAL_CAP_BYTES`]). When a cap is crossed it calls the hook set with
//! [`set_alarm_hook`] at once, which saves the input: the process may not
//! survive what follows (the kernel's OOM killer, or a refused allocation,
//! on which Rust aborts and stable Rust offers no hook to prevent it).
//!
//! Requests are counted per thread: the readers under test allocate on the
//! thread that calls them.

// The workspace denies unsafe code. A global allocator cannot be written
// without it (`GlobalAlloc` is an unsafe trait); every method below only
// forwards to `std::alloc::System` with the caller's own arguments, so the
// allocator's contract is the system allocator's.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::OnceLock;

/// A single allocation larger than this is a finding (512 MiB: far above
/// anything a reader needs for the inputs the fuzzer makes, which are at
/// most a few MiB).
pub const ALLOCATION_CAP_BYTES: usize = 512 << 20;

/// All the bytes one input may ask for, freed or not, before it is a finding
/// (8 GiB): a reader that makes millions of small allocations never trips
/// the single-allocation cap but can still exhaust the machine.
pub const TOTAL_CAP_BYTES: u64 = 8 << 30;

/// The system allocator, noting over-cap requests (see the module docs).
pub struct CappedAllocator;

#[global_allocator]
static GLOBAL: CappedAllocator = CappedAllocator;

/// What the allocator reports to the alarm hook while an input runs, so the
/// input is saved even if the process does not survive it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Alarm {
    /// A single request above [`ALLOCATION_CAP_BYTES`] (given, lazily mapped).
    OverCap(usize),
    /// The input's requests passed [`TOTAL_CAP_BYTES`] in all.
    Total(u64),
    /// An over-cap request the system refused: the process aborts next.
    Failed(usize),
}

/// What this thread asked for since the previous [`take_usage`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Usage {
    /// The largest single request above [`ALLOCATION_CAP_BYTES`] (0: none).
    pub largest_over_cap: usize,
    /// All bytes requested (reallocations count their new size).
    pub total_bytes: u64,
}

thread_local! {
    static USAGE: Cell<Usage> = const { Cell::new(Usage { largest_over_cap: 0, total_bytes: 0 }) };
    /// Set while the alarm hook runs, so its own allocations pass unnoted.
    static IN_HOOK: Cell<bool> = const { Cell::new(false) };
}

static ALARM_HOOK: OnceLock<fn(Alarm)> = OnceLock::new();

/// Sets the function called when an allocation crosses a cap (before the
/// process aborts, for [`Alarm::Failed`]). Only the first call has an effect.
pub fn set_alarm_hook(hook: fn(Alarm)) {
    let _ = ALARM_HOOK.set(hook);
}

/// What this thread asked for since the previous call, and resets it.
#[must_use]
pub fn take_usage() -> Usage {
    USAGE.try_with(|u| u.replace(Usage::default())).unwrap_or_default()
}

/// Notes a request of `size` bytes whose result is `ptr`.
fn note(size: usize, ptr: *mut u8) {
    if IN_HOOK.try_with(Cell::get).unwrap_or(true) {
        return;
    }
    let Ok(before) = USAGE.try_with(Cell::get) else { return };
    let mut after = before;
    after.total_bytes = before.total_bytes.saturating_add(size as u64);
    if size > ALLOCATION_CAP_BYTES {
        after.largest_over_cap = before.largest_over_cap.max(size);
    }
    let _ = USAGE.try_with(|u| u.set(after));
    let alarm = if ptr.is_null() && size > ALLOCATION_CAP_BYTES {
        Some(Alarm::Failed(size))
    } else if size > ALLOCATION_CAP_BYTES {
        Some(Alarm::OverCap(size))
    } else if before.total_bytes <= TOTAL_CAP_BYTES && after.total_bytes > TOTAL_CAP_BYTES {
        Some(Alarm::Total(after.total_bytes))
    } else {
        None
    };
    if let (Some(alarm), Some(hook)) = (alarm, ALARM_HOOK.get()) {
        let _ = IN_HOOK.try_with(|h| h.set(true));
        hook(alarm);
        let _ = IN_HOOK.try_with(|h| h.set(false));
    }
}

// SAFETY: every method forwards to `System` with the arguments it was given,
// so the `GlobalAlloc` contract holds as it does for `System`; `note` only
// reads the size and the returned pointer and never touches the memory.
unsafe impl GlobalAlloc for CappedAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller upholds `GlobalAlloc::alloc`'s contract for `layout`.
        let ptr = unsafe { System.alloc(layout) };
        note(layout.size(), ptr);
        ptr
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as for `alloc`.
        let ptr = unsafe { System.alloc_zeroed(layout) };
        note(layout.size(), ptr);
        ptr
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System` with this `layout` (every allocation here does).
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: `ptr` came from `System` with `layout`; the caller upholds the rest.
        let new = unsafe { System.realloc(ptr, layout, new_size) };
        note(new_size, new);
        new
    }
}
