//! Vertex and index storage shared with Embree.

use std::ops::Deref;

/// A vertex position as Embree's `RTC_FORMAT_FLOAT3` expects it.
pub type Vertex = [f32; 3];
/// Three vertex indices as Embree's `RTC_FORMAT_UINT3` expects them.
pub type Triangle = [u32; 3];
/// A sphere as Embree's `RTC_FORMAT_FLOAT4` point expects it: centre and radius.
pub type SpherePoint = [f32; 4];

/// A buffer with one spare element at its end.
///
/// Embree reads buffer elements with 16-byte vector loads, so the last
/// element of a 12-byte layout must be followed by readable memory (Embree 4
/// API docs, `rtcSetSharedGeometryBuffer`). The spare element is hidden: the
/// buffer derefs to the elements the caller gave.
#[derive(Debug, Clone, PartialEq)]
pub struct PaddedBuffer<T: Copy + Default> {
    items: Vec<T>,
}

impl<T: Copy + Default> PaddedBuffer<T> {
    pub fn new(mut items: Vec<T>) -> Self {
        items.reserve_exact(1);
        items.push(T::default());
        Self { items }
    }

    /// Pointer to the first element, valid for `len() + 1` elements.
    pub(crate) fn padded_ptr(&self) -> *const T {
        self.items.as_ptr()
    }

    /// Bytes held, the padding included.
    pub fn byte_size(&self) -> usize {
        self.items.capacity() * std::mem::size_of::<T>()
    }
}

impl PaddedBuffer<Vertex> {
    /// Vertex `i` and the 4 bytes after it, in one 16-byte load: the
    /// spare element makes them readable for the last vertex too. Lane 3
    /// is whatever follows (the next vertex's `x`, or the padding's 0).
    ///
    /// # Panics
    /// If `i` is out of range, like indexing.
    #[inline(always)]
    pub fn load4(&self, i: usize) -> [f32; 4] {
        assert!(i < self.items.len() - 1, "vertex index {i} out of range");
        // SAFETY: `i + 1 < items.len()`, so the 16 bytes from element `i`
        // (12 of its own, 4 of element `i + 1`) lie inside the allocation;
        // `read_unaligned` needs no alignment, and every bit pattern is a
        // valid `f32`.
        unsafe { std::ptr::read_unaligned(self.items.as_ptr().add(i).cast::<[f32; 4]>()) }
    }
}

impl<T: Copy + Default> Deref for PaddedBuffer<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.items[..self.items.len() - 1]
    }
}

impl<T: Copy + Default> From<Vec<T>> for PaddedBuffer<T> {
    fn from(items: Vec<T>) -> Self {
        Self::new(items)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn padding_is_hidden() {
        let b = PaddedBuffer::new(vec![[1.0f32, 2.0, 3.0]]);
        assert_eq!(b.len(), 1);
        assert_eq!(b[0], [1.0, 2.0, 3.0]);
        assert!(b.byte_size() >= 24);
    }

    #[test]
    fn vertex_loads_read_every_vertex_including_the_last() {
        let b = PaddedBuffer::new(vec![[1.0f32, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        assert_eq!(b.load4(0), [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(b.load4(1), [4.0, 5.0, 6.0, 0.0]);
        let past = std::panic::catch_unwind(|| b.load4(2));
        assert!(past.is_err(), "the padding is not a vertex");
    }
}
