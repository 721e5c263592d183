//! The global allocator of every process that links this crate (the fuzz
//! binary and its tests): the system allocator, plus a note of each single
//! request above [`ALLOCATION_CAP_BYTES`], so that a size field a reader
//! trusts becomes a finding instead of an aborted process.
//!
//! An over-cap request is still passed to the system allocator: on Linux a
//! large block is mapped lazily, so asking costs nothing until it is written,
//! and the fuzz loop reports the request after the input ran
//! ([`take_largest_over_cap`]). Only when the system refuses (more than the
//! machine can map) is the process lost: Rust aborts on a failed allocation
//! and stable Rust offers no hook to prevent it, so the allocator first calls
//! the hook set with [`set_failed_allocation_hook`], which saves the input.
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

/// The system allocator, noting over-cap requests (see the module docs).
pub struct CappedAllocator;

#[global_allocator]
static GLOBAL: CappedAllocator = CappedAllocator;

thread_local! {
    /// The largest over-cap request of this thread since the last take.
    static LARGEST_OVER_CAP: Cell<usize> = const { Cell::new(0) };
    /// Set while the failed-allocation hook runs, so its own allocations pass.
    static IN_HOOK: Cell<bool> = const { Cell::new(false) };
}

static FAILED_ALLOCATION_HOOK: OnceLock<fn(usize)> = OnceLock::new();

/// Sets the function called with the size when an over-cap request fails,
/// just before the process aborts. Only the first call has an effect.
pub fn set_failed_allocation_hook(hook: fn(usize)) {
    let _ = FAILED_ALLOCATION_HOOK.set(hook);
}

/// The largest single request above [`ALLOCATION_CAP_BYTES`] made by this
/// thread since the previous call (0 for none), and resets it.
#[must_use]
pub fn take_largest_over_cap() -> usize {
    LARGEST_OVER_CAP.try_with(|c| c.replace(0)).unwrap_or(0)
}

/// Notes a request of `size` bytes whose result is `ptr`.
fn note(size: usize, ptr: *mut u8) {
    if size <= ALLOCATION_CAP_BYTES {
        return;
    }
    let _ = LARGEST_OVER_CAP.try_with(|c| c.set(c.get().max(size)));
    if ptr.is_null() && IN_HOOK.try_with(|h| !h.replace(true)).unwrap_or(false) {
        if let Some(hook) = FAILED_ALLOCATION_HOOK.get() {
            hook(size);
        }
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
