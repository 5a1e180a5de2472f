//! A list that grows a chunk at a time and never copies what it holds.
//!
//! The collapse engines make one record a collapse while the build's memory is near its peak:
//! reserved for every collapse at the start, the records' room (44 bytes an input vertex) was
//! part of that peak; grown as a `Vec` doubles, each doubling would hold the old and the new
//! room at once. Chunks add only what the collapses fill, and are joined into one `Vec` when the
//! engine's own arrays are gone.

use alloc::vec::Vec;

/// Items in order, in chunks of `chunk` items.
pub(crate) struct Chunks<T> {
    chunks: Vec<Vec<T>>,
    chunk: usize,
    len: usize,
}

impl<T> Chunks<T> {
    /// Empty, for about `expected` items: a sixteenth of them a chunk (at least 64).
    pub fn for_about(expected: usize) -> Chunks<T> {
        Chunks {
            chunks: Vec::new(),
            chunk: (expected / 16).max(64),
            len: 0,
        }
    }

    /// Appends `item`.
    pub fn push(&mut self, item: T) {
        match self.chunks.last_mut() {
            Some(last) if last.len() < self.chunk => last.push(item),
            _ => {
                let mut fresh = Vec::with_capacity(self.chunk);
                fresh.push(item);
                self.chunks.push(fresh);
            }
        }
        self.len += 1;
    }

    /// Items pushed.
    pub fn len(&self) -> usize {
        self.len
    }

    /// The last item pushed.
    pub fn last(&self) -> Option<&T> {
        self.chunks.last().and_then(|c| c.last())
    }

    /// The items in one `Vec`, each chunk freed once copied.
    pub fn into_vec(self) -> Vec<T> {
        let mut all = Vec::with_capacity(self.len);
        for chunk in self.chunks {
            all.extend(chunk);
        }
        all
    }
}

#[cfg(test)]
mod tests {
    use super::Chunks;
    use alloc::vec::Vec;

    /// Pushed items come out in order, across chunk boundaries, as many as were pushed.
    #[test]
    fn chunks_keep_the_order() {
        for count in [0usize, 1, 63, 64, 65, 1000, 4097] {
            let mut chunks = Chunks::for_about(1000);
            for k in 0..count {
                chunks.push(k);
                assert_eq!(chunks.last(), Some(&k));
            }
            let all = chunks.into_vec();
            assert_eq!(all, (0..count).collect::<Vec<_>>());
            assert_eq!(all.capacity(), count);
        }
    }
}
