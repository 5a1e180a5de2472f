//! Edges a collapse found illegal, by endpoint, to be retried when a later collapse changes
//! that endpoint's ring.
//!
//! Few vertices ever have any, so the lists live in a map; but every collapse asks about each
//! vertex of its ring, so a flag per vertex id answers "none" without a search of the map.

use alloc::collections::BTreeMap;
use alloc::vec::Vec;

/// The rejected edges of each vertex id.
#[derive(Default)]
pub(crate) struct Rejected {
    lists: BTreeMap<u32, Vec<u32>>,
    /// Whether `lists` has an entry for the id.
    listed: Vec<bool>,
}

impl Rejected {
    /// Room for the flags of `ids` vertex ids (more grow the flags as they come).
    pub fn with_ids(ids: usize) -> Rejected {
        Rejected {
            lists: BTreeMap::new(),
            listed: alloc::vec![false; ids],
        }
    }

    fn flag(&mut self, v: u32) -> &mut bool {
        let i = v as usize;
        if i >= self.listed.len() {
            self.listed.resize(i + 1, false);
        }
        &mut self.listed[i]
    }

    /// Records the illegal edge `a-b` under both endpoints.
    pub fn add(&mut self, a: u32, b: u32) {
        for (x, y) in [(a, b), (b, a)] {
            *self.flag(x) = true;
            self.lists.entry(x).or_default().push(y);
        }
    }

    /// Takes vertex `v`'s list (empty when it has none).
    pub fn take(&mut self, v: u32) -> Vec<u32> {
        if !self.listed.get(v as usize).copied().unwrap_or(false) {
            return Vec::new();
        }
        *self.flag(v) = false;
        self.lists.remove(&v).unwrap_or_default()
    }

    /// Drops `x` from vertex `v`'s list, and the list once empty.
    pub fn drop_from(&mut self, v: u32, x: u32) {
        if !self.listed.get(v as usize).copied().unwrap_or(false) {
            return;
        }
        if let Some(list) = self.lists.get_mut(&v) {
            list.retain(|&z| z != x);
            if list.is_empty() {
                self.lists.remove(&v);
                *self.flag(v) = false;
            }
        }
    }
}
