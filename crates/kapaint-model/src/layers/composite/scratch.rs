//! Reused buffers for compositing: a tile's planes are allocated once per thread, not once
//! per tile. (Allocating and freeing them per tile made the allocator hand the memory back to
//! the system after every dab and fault it in again on the next: a fifth of a dab's time.)

use std::cell::RefCell;

/// Buffers kept per thread: enough for a stack nested a few groups deep.
const KEPT: usize = 64;

thread_local! {
    static FREE: RefCell<Vec<Vec<f32>>> = const { RefCell::new(Vec::new()) };
}

/// A buffer of `len` copies of `value`, reusing one this thread gave back.
pub(super) fn buffer(len: usize, value: f32) -> Vec<f32> {
    let mut v = overwritten(len);
    v.fill(value);
    v
}

/// A buffer of `len` entries whose values are left as they were (the caller writes every
/// entry before reading it), reusing one this thread gave back.
pub(super) fn overwritten(len: usize) -> Vec<f32> {
    let reused = FREE.with_borrow_mut(Vec::pop);
    match reused {
        Some(mut v) => {
            if v.len() >= len {
                v.truncate(len);
            } else {
                v.resize(len, 0.0);
            }
            v
        }
        None => vec![0.0; len],
    }
}

/// Gives `v` back for [`buffer`] and [`overwritten`] to reuse on this thread.
pub(super) fn recycle(v: Vec<f32>) {
    FREE.with_borrow_mut(|free| {
        if free.len() < KEPT {
            free.push(v);
        }
    });
}
