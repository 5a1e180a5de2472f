//! Something of each triangle filed under each of its corners: for every vertex, its triangles'
//! items side by side in one flat array (a counting sort on the vertex), in triangle order. The
//! input checks file each triangle's link edge under its corners; the remesher files the
//! triangles themselves.

use alloc::vec;
use alloc::vec::Vec;

/// Items filed by vertex: vertex `v`'s are `items[start[v]..start[v + 1]]`.
pub(crate) struct Around<T> {
    start: Vec<u32>,
    items: Vec<T>,
}

impl<T: Copy + Default> Around<T> {
    /// For each of the `n` vertices, `item(t, k)` for each triangle `t` of `triangles` whose
    /// corner `k` it is, in triangle order (every corner is below `n`).
    pub fn filed(n: usize, triangles: &[[u32; 3]], item: impl Fn(u32, usize) -> T) -> Around<T> {
        let mut start = vec![0u32; n + 1];
        for tri in triangles {
            for &v in tri {
                start[v as usize + 1] += 1;
            }
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        let mut next = start.clone();
        let mut items = vec![T::default(); triangles.len() * 3];
        for (t, tri) in triangles.iter().enumerate() {
            for (k, &v) in tri.iter().enumerate() {
                let at = &mut next[v as usize];
                items[*at as usize] = item(t as u32, k);
                *at += 1;
            }
        }
        Around { start, items }
    }

    /// Vertex `v`'s items.
    pub fn of(&self, v: u32) -> &[T] {
        let v = v as usize;
        &self.items[self.start[v] as usize..self.start[v + 1] as usize]
    }

    /// Vertex `v`'s items, to reorder.
    pub fn of_mut(&mut self, v: u32) -> &mut [T] {
        let v = v as usize;
        &mut self.items[self.start[v] as usize..self.start[v + 1] as usize]
    }
}

impl Around<u32> {
    /// The triangles around each of the `n` vertices, by index, in triangle order.
    pub fn triangles(n: usize, triangles: &[[u32; 3]]) -> Around<u32> {
        Around::filed(n, triangles, |t, _| t)
    }
}
