//! Channel-sounder impulse responses (being written: see issue #3).
