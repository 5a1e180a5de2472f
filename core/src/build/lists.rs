//! Each live vertex's faces and neighbours, in one allocation per vertex.
//!
//! The collapse engine keeps, by slot, the faces around each live vertex and its sorted ring of
//! neighbours. Two `Vec`s a vertex cost 48 bytes of headers before any id; here both lists
//! share one boxed slice, `[faces, ring, faces..., ring..., room...]` (room left where a list
//! shrank), 16 bytes of header and 8 of lengths. The lists change in only three ways, none of
//! which grows a list in place: a face leaves its third corner's list, a neighbour's ring swaps
//! the collapsing pair for the new vertex (the ring loses one or two ids and gains one), and the
//! new vertex gets lists of its own (a new allocation, at its exact length).

use alloc::boxed::Box;
use alloc::vec::Vec;

/// The lists of each slot (see the module documentation).
#[derive(Default)]
pub(crate) struct Lists {
    slots: Vec<Box<[u32]>>,
}

/// The faces of lists `l` (a slot's, or taken by [`Lists::take`]).
#[inline]
pub(crate) fn faces_in(l: &[u32]) -> &[u32] {
    match l {
        [f, _, rest @ ..] => rest.get(..*f as usize).unwrap_or(&[]),
        _ => &[],
    }
}

/// The ring of lists `l` (a slot's, or taken by [`Lists::take`]).
#[inline]
pub(crate) fn ring_in(l: &[u32]) -> &[u32] {
    match l {
        [f, r, rest @ ..] => rest.get(*f as usize..(*f + *r) as usize).unwrap_or(&[]),
        _ => &[],
    }
}

/// The ring of lists `l`, to change in place; `None` when `l` holds none.
#[inline]
fn ring_in_mut(l: &mut [u32]) -> Option<&mut [u32]> {
    match l {
        [f, r, rest @ ..] => {
            let start = *f as usize;
            rest.get_mut(start..start + *r as usize)
        }
        _ => None,
    }
}

/// Where an id of [`Merged`] is: in the first list, the second, or both.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum In {
    First,
    Second,
    Both,
}

/// The ids of two sorted lists without repeats, in order and once each, with the lists they are
/// in: one walk of both gives a collapse's faces and ring in the order a sort would, and which
/// end each came from (read off slices, with no bounds check apiece).
pub(crate) struct Merged<'l> {
    first: &'l [u32],
    second: &'l [u32],
}

impl<'l> Merged<'l> {
    pub fn new(first: &'l [u32], second: &'l [u32]) -> Merged<'l> {
        Merged { first, second }
    }
}

impl Iterator for Merged<'_> {
    type Item = (u32, In);

    #[inline]
    fn next(&mut self) -> Option<(u32, In)> {
        match (self.first.split_first(), self.second.split_first()) {
            (Some((&x, xs)), Some((&y, ys))) => {
                if x < y {
                    self.first = xs;
                    Some((x, In::First))
                } else if y < x {
                    self.second = ys;
                    Some((y, In::Second))
                } else {
                    (self.first, self.second) = (xs, ys);
                    Some((x, In::Both))
                }
            }
            (Some((&x, xs)), None) => {
                self.first = xs;
                Some((x, In::First))
            }
            (None, Some((&y, ys))) => {
                self.second = ys;
                Some((y, In::Second))
            }
            (None, None) => None,
        }
    }
}

/// Lists holding `faces` and `ring`, at their exact length.
fn made(faces: &[u32], ring: &[u32]) -> Box<[u32]> {
    let mut l = Vec::with_capacity(2 + faces.len() + ring.len());
    l.extend_from_slice(&[faces.len() as u32, ring.len() as u32]);
    l.extend_from_slice(faces);
    l.extend_from_slice(ring);
    l.into_boxed_slice()
}

impl Lists {
    /// Room for `n` slots.
    pub fn with_capacity(n: usize) -> Lists {
        Lists {
            slots: Vec::with_capacity(n),
        }
    }

    /// Appends a slot with these lists (at their exact length).
    pub fn push(&mut self, faces: &[u32], ring: &[u32]) {
        self.slots.push(made(faces, ring));
    }

    /// The faces around slot `s`'s vertex.
    #[inline]
    pub fn faces(&self, s: usize) -> &[u32] {
        self.slots.get(s).map_or(&[], |l| faces_in(l))
    }

    /// The sorted neighbours of slot `s`'s vertex.
    #[inline]
    pub fn ring(&self, s: usize) -> &[u32] {
        self.slots.get(s).map_or(&[], |l| ring_in(l))
    }

    /// The faces and the sorted neighbours of slot `s`'s vertex, from one look-up of its lists
    /// (the legality test reads both of each end's: looked up one at a time, each list cost a
    /// search of the slots and of their lengths).
    #[inline]
    pub fn both(&self, s: usize) -> (&[u32], &[u32]) {
        self.slots
            .get(s)
            .map_or((&[], &[]), |l| (faces_in(l), ring_in(l)))
    }

    /// Every slot's ring length, summed.
    pub fn ring_total(&self) -> usize {
        self.slots.iter().map(|l| ring_in(l).len()).sum()
    }

    /// Whether each slot has faces.
    pub fn has_faces(&self) -> impl Iterator<Item = bool> + '_ {
        self.slots.iter().map(|l| !faces_in(l).is_empty())
    }

    /// Takes slot `s`'s lists out (leaving none), for [`faces_in`] and [`ring_in`].
    pub fn take(&mut self, s: usize) -> Box<[u32]> {
        self.slots
            .get_mut(s)
            .map(core::mem::take)
            .unwrap_or_default()
    }

    /// Gives slot `s` these lists: in `room` (lists taken out and no longer needed, whose
    /// length is kept) when they fit there, else at their exact length. A collapse's merged
    /// lists rarely fit in one end's, but when they do (its lists had shrunk, or the other
    /// end's were short) an allocation and a free are saved: about 1% of the collapses'
    /// instructions on the bunny.
    pub fn set_in(&mut self, s: usize, faces: &[u32], ring: &[u32], mut room: Box<[u32]>) {
        let Some(l) = self.slots.get_mut(s) else {
            return;
        };
        let (nf, nr) = (faces.len(), ring.len());
        match room.get_mut(..2 + nf + nr) {
            Some(into) => {
                into[0] = nf as u32;
                into[1] = nr as u32;
                into[2..2 + nf].copy_from_slice(faces);
                into[2 + nf..].copy_from_slice(ring);
                *l = room;
            }
            None => *l = made(faces, ring),
        }
    }

    /// Removes face `f` from slot `s`'s faces (keeping their order).
    pub fn remove_face(&mut self, s: usize, f: u32) {
        let Some(l) = self.slots.get_mut(s) else {
            return;
        };
        let (nf, nr) = (l[0] as usize, l[1] as usize);
        let Some(k) = faces_in(l).iter().position(|&g| g == f) else {
            return;
        };
        // The faces after it and the whole ring move down one.
        l.copy_within(2 + k + 1..2 + nf + nr, 2 + k);
        l[0] -= 1;
    }

    /// In slot `s`'s ring, replaces `old` by `p`, which is larger than every id in it and so goes
    /// last. A collapse's neighbour of only one end has that end alone in its ring: one walk
    /// from the end shifts what follows `old` down onto it (a search for either of two ids,
    /// and a filter of the rest for either, took half as many instructions again).
    pub fn replace_in_ring(&mut self, s: usize, old: u32, p: u32) {
        let Some(ring) = self.slots.get_mut(s).and_then(|l| ring_in_mut(l)) else {
            return;
        };
        debug_assert!(
            ring.contains(&old),
            "a ring of the collapsing pair holds one of it"
        );
        // From the end down to `old`, each id takes the place of the one before it.
        let mut next = p;
        for x in ring.iter_mut().rev() {
            let here = core::mem::replace(x, next);
            if here == old {
                break;
            }
            next = here;
        }
    }

    /// In slot `s`'s ring, replaces `a` and `b` by `p`, which is larger than every id in it
    /// and so goes last. The ring holds `a` or `b`, so it does not grow.
    pub fn swap_in_ring(&mut self, s: usize, (a, b): (u32, u32), p: u32) {
        let Some(l) = self.slots.get_mut(s) else {
            return;
        };
        let (nf, nr) = (l[0] as usize, l[1] as usize);
        let ring = &mut l[2 + nf..2 + nf + nr];
        let Some(first) = ring.iter().position(|&x| x == a || x == b) else {
            // Neither is there (never, for a ring of the pair's): keep `p` out rather than grow.
            debug_assert!(false, "a ring of the collapsing pair holds one of it");
            return;
        };
        // Up to the first of the pair nothing moves; after it, the rest closes up.
        let mut kept = first;
        for k in first + 1..nr {
            let x = ring[k];
            if x != a && x != b {
                ring[kept] = x;
                kept += 1;
            }
        }
        ring[kept] = p;
        l[1] = kept as u32 + 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_change_as_a_collapse_changes_them() {
        let mut l = Lists::with_capacity(3);
        l.push(&[4, 7, 9], &[1, 2, 5]);
        l.push(&[], &[]);
        l.push(&[3], &[0, 6, 8, 9]);
        assert_eq!((l.faces(0), l.ring(0)), (&[4, 7, 9][..], &[1, 2, 5][..]));
        assert_eq!(l.has_faces().collect::<Vec<_>>(), [true, false, true]);
        assert_eq!(l.ring_total(), 7);
        l.remove_face(0, 7);
        assert_eq!((l.faces(0), l.ring(0)), (&[4, 9][..], &[1, 2, 5][..]));
        l.remove_face(0, 8);
        assert_eq!(l.faces(0), &[4, 9]);
        // Both of the pair in the ring: it shrinks; one: the same length.
        l.swap_in_ring(2, (6, 9), 10);
        assert_eq!((l.faces(2), l.ring(2)), (&[3][..], &[0, 8, 10][..]));
        l.swap_in_ring(0, (2, 3), 11);
        assert_eq!(l.ring(0), &[1, 5, 11]);
        let taken = l.take(0);
        assert_eq!(
            (faces_in(&taken), ring_in(&taken)),
            (&[4, 9][..], &[1, 5, 11][..])
        );
        assert!(l.faces(0).is_empty() && l.ring(0).is_empty());
        l.set_in(0, &[1, 2], &[3], taken);
        assert_eq!((l.faces(0), l.ring(0)), (&[1, 2][..], &[3][..]));
        // Too long for the room: at their exact length.
        l.set_in(0, &[1, 2, 3, 4, 5], &[6, 7, 8, 9], Box::new([]));
        assert_eq!(l.faces(0), &[1, 2, 3, 4, 5]);
        assert_eq!(l.ring(0), &[6, 7, 8, 9]);
        assert_eq!(l.faces(7), &[] as &[u32]);
    }
}
