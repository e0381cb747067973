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
}
