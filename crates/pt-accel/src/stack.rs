//! A fixed-capacity traversal stack that costs nothing to create.
//!
//! A `[u64; 64]` stack is zeroed on every query (512 bytes of stores before the first node
//! test), which is a measurable share of a short query. This stack leaves its slots
//! uninitialised and tracks how many are written: every slot below `len` has been written, and
//! only those are read. That invariant is the whole safety argument of the one `unsafe`
//! operation here (reading a slot as initialised); pushing past the capacity panics, as indexing
//! a full array would.

use std::mem::MaybeUninit;

/// At most `N` values of `T`, last in first out.
pub(crate) struct Stack<T: Copy, const N: usize> {
    slots: [MaybeUninit<T>; N],
    /// Slots `0..len` are initialised.
    len: usize,
}

impl<T: Copy, const N: usize> Stack<T, N> {
    /// An empty stack (no slot is written).
    #[inline(always)]
    pub fn new() -> Self {
        Self {
            slots: [const { MaybeUninit::uninit() }; N],
            len: 0,
        }
    }

    #[inline(always)]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Push `v`.
    ///
    /// # Panics
    /// When the stack holds `N` values already.
    #[inline(always)]
    pub fn push(&mut self, v: T) {
        self.slots[self.len].write(v);
        self.len += 1;
    }

    /// The value in slot `i`.
    ///
    /// # Panics
    /// When `i` is not below [`Self::len`].
    #[inline(always)]
    pub fn get(&self, i: usize) -> T {
        assert!(i < self.len);
        // SAFETY: slots below `len` have been written (by `push` or `set`).
        unsafe { self.slots[i].assume_init() }
    }

    /// Overwrite slot `i`, which must be below [`Self::len`].
    #[inline(always)]
    pub fn set(&mut self, i: usize, v: T) {
        assert!(i < self.len);
        self.slots[i].write(v);
    }

    /// Remove and return the top value.
    #[inline(always)]
    pub fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: slot `len` (the old top) was below the old `len`, so it has been written.
        Some(unsafe { self.slots[self.len].assume_init() })
    }
}

impl<T: Copy + Ord, const N: usize> Stack<T, N> {
    /// Push `v` into the sorted run of slots `base..len` (ascending from the top down, so that
    /// the smallest ends on top): slots above `v` move up one.
    #[inline(always)]
    pub fn insert_sorted(&mut self, base: usize, v: T) {
        self.push(v);
        let mut j = self.len - 1;
        while j > base && self.get(j - 1) < v {
            let below = self.get(j - 1);
            self.set(j, below);
            j -= 1;
        }
        self.set(j, v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_pop_and_sorted_insertion() {
        let mut s = Stack::<u64, 8>::new();
        assert_eq!(s.pop(), None);
        s.push(7);
        let base = s.len();
        for v in [5, 9, 1, 5] {
            s.insert_sorted(base, v);
        }
        // The run above `base` is descending, so the smallest pops first.
        let popped: Vec<u64> = std::iter::from_fn(|| s.pop()).collect();
        assert_eq!(popped, [1, 5, 5, 9, 7]);
    }

    #[test]
    #[should_panic]
    fn pushing_past_the_capacity_panics() {
        let mut s = Stack::<u32, 2>::new();
        for v in 0..3 {
            s.push(v);
        }
    }
}
