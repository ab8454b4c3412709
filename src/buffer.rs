//! A fixed-capacity buffer whose every element is always initialised.
//!
//! `heapless::Vec` keeps its spare capacity uninitialised, so growing it
//! safely means writing each new element one `push` at a time (about nine
//! instructions per 32-byte element on the Cortex-M4F). The per-frame
//! buffers here are overwritten in full right after they are sized, so
//! they are plain arrays filled once at construction plus a length:
//! resizing is setting the length, and copying is one slice copy. Only
//! the first `len` elements are part of the value (equality, `Debug`,
//! `defmt`).

use core::fmt;

#[derive(Clone)]
pub(crate) struct Buffer<T: Copy, const N: usize> {
    items: [T; N],
    len: usize,
}

impl<T: Copy, const N: usize> Buffer<T, N> {
    /// An empty buffer; `fill` is what unused elements hold.
    pub(crate) const fn new(fill: T) -> Self {
        Self {
            items: [fill; N],
            len: 0,
        }
    }

    /// The live elements.
    pub(crate) fn as_slice(&self) -> &[T] {
        self.items.get(..self.len).unwrap_or(&[])
    }

    /// The live elements, mutably.
    pub(crate) fn as_mut_slice(&mut self) -> &mut [T] {
        self.items.get_mut(..self.len).unwrap_or(&mut [])
    }

    /// All `N` elements, live or not, to be written in place before
    /// [`Buffer::set_len`] makes them live (the wire decoder's points).
    pub(crate) fn storage_mut(&mut self) -> &mut [T; N] {
        &mut self.items
    }

    /// Make the first `len` elements live (at most `N`); elements that
    /// become live hold whatever they last held.
    pub(crate) fn set_len(&mut self, len: usize) {
        self.len = len.min(N);
    }

    /// Become a copy of `src` (its first `N` elements).
    ///
    /// In blocks of four elements: a copy of known small size is inlined
    /// as a few multi-register loads and stores, where a copy of unknown
    /// size calls the library `memcpy`, a word-by-word loop on this target
    /// (twice the instructions for 8-byte elements).
    pub(crate) fn copy_from(&mut self, src: &[T]) {
        self.set_len(src.len());
        let n = self.len;
        if let (Some(d), Some(s)) = (self.items.get_mut(..n), src.get(..n)) {
            let (mut dc, mut sc) = (d.chunks_exact_mut(4), s.chunks_exact(4));
            for (d4, s4) in (&mut dc).zip(&mut sc) {
                if let (Ok(d4), Ok(s4)) = (<&mut [T; 4]>::try_from(d4), <&[T; 4]>::try_from(s4)) {
                    *d4 = *s4;
                }
            }
            for (d1, s1) in dc.into_remainder().iter_mut().zip(sc.remainder()) {
                *d1 = *s1;
            }
        }
    }
}

impl<T: Copy + PartialEq, const N: usize> PartialEq for Buffer<T, N> {
    fn eq(&self, other: &Self) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl<T: Copy + fmt::Debug, const N: usize> fmt::Debug for Buffer<T, N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.as_slice().fmt(f)
    }
}

#[cfg(feature = "defmt")]
impl<T: Copy + defmt::Format, const N: usize> defmt::Format for Buffer<T, N> {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "{}", self.as_slice())
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::format;

    #[test]
    fn length_and_copies() {
        let mut b = Buffer::<u32, 4>::new(7);
        assert_eq!(b.as_slice(), &[] as &[u32]);
        b.set_len(2);
        assert_eq!(b.as_slice(), &[7, 7]);
        b.copy_from(&[1, 2, 3, 4, 5]);
        assert_eq!(b.as_slice(), &[1, 2, 3, 4]);
        b.set_len(9);
        assert_eq!(b.as_slice().len(), 4);
        let mut c = Buffer::<u32, 4>::new(0);
        c.copy_from(&[1, 2, 3, 4]);
        assert_eq!(b, c);
        c.set_len(3);
        assert_ne!(b, c);
        assert_eq!(format!("{c:?}"), "[1, 2, 3]");
    }
}
