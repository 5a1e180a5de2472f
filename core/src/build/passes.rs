//! The balanced forest ([`super::BuildOptions::balanced`]) made in passes: the merge-tree
//! paper's region-of-influence marking (Berkey and Song, "Dynamic View Dependent Level of
//! Detail", §3.1: a collapse blocks the collapses around it until no unblocked one is left), run
//! the way meshoptimizer simplifies (Kapoulkine, meshoptimizer's `simplify`: the costs sorted
//! once a pass over flat arrays, not kept in a heap).
//!
//! [`super::collapse::Engine`] keeps a heap of every edge's cost, collapses the cheapest legal
//! edge and updates each vertex's lists of faces and neighbours as it goes; run balanced it also
//! pushed every blocked edge again at each pass's end. Here each pass walks the edges in order of
//! cost and collapses every legal edge whose region no earlier collapse of the pass touched: a
//! collapse marks the corners of the triangles around its two ends, and an edge with an end or a
//! wing marked waits for the next pass. What a collapse reads (the triangles around its ends and
//! wings, their corners and positions) is therefore as the pass found it, so the triangles around
//! each vertex sit in two flat arrays filed at the pass's start, and between passes only the
//! marked vertices' lists are brought up to date. Costs are kept from pass to pass: only the edges
//! of the vertices a pass made are measured again (no other edge's quadrics or ends changed), and
//! merged into the sorted list. An edge found illegal is not tried again until a collapse touches
//! one of its ends.
//!
//! The collapses are of the heap engine's kind (the same costs, placements, legality tests and
//! records), so the hierarchy is made from them the same way ([`super::attributes`]). On the
//! bunny a pass merges about an eighth of the live vertices, and 75 passes build the forest.

use alloc::vec;
use alloc::vec::Vec;

use super::chunks::Chunks;
use super::closest::Surface;
use super::collapse::{
    after, color_of, cost_at, cost_key, edge_wings, face_sums, merge_sums, placement, stays_up,
    Collapse, Collapsed, Split,
};
use super::input::Borders;
use super::positions::Positions;
use super::quadric::Quadric;
use super::vec3::{cross, normalize, sub, Vec3d};
use super::{BuildOptions, Cost, ErrorBound, InputMesh, NONE};

/// An edge waiting to collapse: its cost's `f32` bits (non-negative floats order like their
/// bits), its ends' vertex ids (`a < b`), and the pass that last found it illegal (0: never).
/// Among equal costs the edge measured first goes first, as in the heap engine: every sort and
/// merge of the list is stable.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Edge {
    key: u32,
    a: u32,
    b: u32,
    tried: u32,
}

/// What an edge's test found.
enum Verdict {
    /// An end or a wing is in a region this pass has touched: next pass.
    Blocked,
    /// Not legal as the mesh stands.
    Illegal,
    /// Legal: collapse it, the new vertex there (and the edge's wings, as `edge_faces` found
    /// them).
    Legal(Vec3d, [u32; 2]),
}

/// The engine. Inside it a live vertex is known by its *slot*, which a collapse's vertex
/// takes over from its first end, so that the triangles' corners, the marks and the filing
/// never need more than one entry per input vertex; vertex ids (which name one position for
/// ever) appear only in the edges and the collapse records.
pub(crate) struct Passes<'o> {
    opts: &'o BuildOptions,
    pos: Positions<'o>,
    color: Vec<Vec3d>,
    /// The input's triangles, their corners as slots.
    faces: Vec<[u32; 3]>,
    face_alive: Vec<bool>,
    /// The live faces, compacted after each pass.
    live: Vec<u32>,
    /// One record a collapse, in chunks (joined once the engine's arrays are gone).
    collapses: Chunks<Collapse>,
    fans: Vec<[u32; 3]>,
    fan_ends: Vec<u32>,
    /// By slot: quadric, area, the live vertex in it, the pass that last touched its region
    /// (0: none yet), and a scratch stamp for sets of neighbours.
    quadric: Vec<Quadric>,
    area: Vec<f64>,
    owner: Vec<u32>,
    mark: Vec<u32>,
    stamp: Vec<u32>,
    stamped: u32,
    /// By vertex id: its slot, and whether it is live (has faces and has not merged).
    slot: Vec<u32>,
    alive: Vec<bool>,
    pub alive_count: usize,
    /// The slots of live vertices, compacted after each pass, and the live faces around each,
    /// brought up to date between passes: slot `s`'s are `around[first[s]..end[s]]`.
    live_slots: Vec<u32>,
    first: Vec<u32>,
    end: Vec<u32>,
    around: Vec<u32>,
    /// The wings of this pass's collapses, each once: the only live slots that lost faces (a
    /// collapse ends just the faces on its edge, whose corners are its ends and wings; the
    /// region it marks keeps every other vertex's faces, renamed in place, out of the pass).
    thinned: Vec<u32>,
    /// Faces alive (three entries each in a compact filing).
    faces_alive: usize,
    /// The edges, cheapest first.
    edges: Vec<Edge>,
    /// Costs computed.
    evaluations: u64,
    surface: Option<Surface>,
    pass: u32,
}

impl<'o> Passes<'o> {
    /// The engine over `mesh` (which has passed the input checks, and whose vertices on a
    /// border they found), every edge measured.
    pub fn new(mesh: &InputMesh<'o>, opts: &'o BuildOptions, on_border: &Borders) -> Passes<'o> {
        let n = mesh.positions.len();
        let ids = n.saturating_sub(1);
        let pos = Positions::new(mesh.positions, ids);
        let faces = mesh.triangles.to_vec();
        let mut color: Vec<Vec3d> = mesh.colors.map_or_else(Vec::new, |c| {
            c.iter().map(|c| c.map(|v| v as f64 / 255.0)).collect()
        });
        let (quadric, area) = face_sums(&pos, &faces, n, !color.is_empty());
        let mut alive = vec![false; n];
        for &v in faces.iter().flatten() {
            alive[v as usize] = true;
        }
        color.reserve_exact(if color.is_empty() { 0 } else { ids });
        alive.reserve_exact(ids);
        let live_slots = (0..n as u32).filter(|&v| alive[v as usize]).collect();
        let mut slot: Vec<u32> = (0..n as u32).collect();
        slot.reserve_exact(ids);
        let mut e = Passes {
            opts,
            pos,
            color,
            face_alive: vec![true; faces.len()],
            live: (0..faces.len() as u32).collect(),
            faces,
            collapses: Chunks::for_about(ids),
            fans: Vec::new(),
            fan_ends: Vec::new(),
            quadric,
            area,
            owner: (0..n as u32).collect(),
            mark: vec![0; n],
            stamp: vec![0; n],
            stamped: 0,
            slot,
            alive_count: alive.iter().filter(|&&a| a).count(),
            alive,
            live_slots,
            first: vec![0; n],
            end: vec![0; n],
            around: Vec::new(),
            thinned: Vec::new(),
            faces_alive: mesh.triangles.len(),
            edges: Vec::new(),
            evaluations: 0,
            surface: (opts.cost == Cost::Color)
                .then(|| Surface::new(mesh.positions, mesh.triangles)),
            pass: 0,
        };
        e.file_faces();
        // Boundary quadrics keep open borders in place, as in the heap engine. Both ends of a
        // border edge are border vertices: that test spares the other edges a walk.
        for f in 0..e.faces.len() {
            let tri = e.faces[f];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if on_border.contains(a) && on_border.contains(b) && e.edge_faces(a, b).1 == 1 {
                    let n = normalize(e.face_normal(tri)).unwrap_or([0.0; 3]);
                    let q = Quadric::boundary(e.pos.get(a), e.pos.get(b), n, 16.0);
                    for v in [a, b] {
                        e.quadric[v as usize] = e.quadric[v as usize].add(&q);
                    }
                }
            }
        }
        let mut ring = Vec::new();
        for v in 0..n as u32 {
            if e.alive[v as usize] {
                e.ring(v, &mut ring);
                for &x in ring.iter().filter(|&&x| x > v) {
                    let edge = e.edge(v, x);
                    e.edges.push(edge);
                }
            }
        }
        let mut scratch = Vec::new();
        sort_by_cost(&mut e.edges, &mut scratch);
        e
    }

    /// Collapses pass after pass until `target` vertices are left or no collapse is legal;
    /// `progress` hears the collapses done after each pass.
    pub fn run(&mut self, target: usize, progress: &mut dyn FnMut(u32)) {
        while self.alive_count > target {
            self.pass += 1;
            // A pass that made nothing marked nothing, so nothing was blocked: every edge left
            // was tried and found illegal.
            let made = self.pass_once(target);
            progress(self.collapses.len() as u32);
            if made == 0 {
                break;
            }
            self.next_pass(made);
        }
    }

    /// One pass over the sorted edges; returns the collapses it made.
    fn pass_once(&mut self, target: usize) -> usize {
        let k = self.pass;
        let mut made = 0;
        for i in 0..self.edges.len() {
            if self.alive_count <= target {
                break;
            }
            let Edge { a, b, tried, .. } = self.edges[i];
            if !self.alive[a as usize] || !self.alive[b as usize] {
                continue;
            }
            let (ma, mb) = (
                self.mark[self.slot[a as usize] as usize],
                self.mark[self.slot[b as usize] as usize],
            );
            // Tested in pass `tried` and found illegal: only a collapse that touched an end since
            // (a mark from that pass, made after the test, or a later one) can have changed that.
            if ma == k || mb == k || (tried != 0 && ma < tried && mb < tried) {
                continue;
            }
            match self.judge(a, b) {
                Verdict::Blocked => {}
                Verdict::Illegal => self.edges[i].tried = k,
                Verdict::Legal(v, wings) => {
                    self.collapse(a, b, v, wings);
                    made += 1;
                }
            }
        }
        made
    }

    /// Files the faces again and merges the new vertices' edges into the sorted list.
    fn next_pass(&mut self, made: usize) {
        let kept = self.drop_dead_edges();
        self.refile();
        let first_new = (self.pos.len() - made) as u32;
        let mut fresh = Vec::new();
        let mut ring = Vec::new();
        for p in first_new..self.pos.len() as u32 {
            self.ring(p, &mut ring);
            for &x in &ring {
                // Vertices made in one pass are never neighbours, but an edge is listed once.
                if x < first_new || p < x {
                    fresh.push(self.edge(p.min(x), p.max(x)));
                }
            }
        }
        // Both lists are freed before the next pass: the builder's peak heap may come later.
        sort_by_cost(&mut fresh, &mut Vec::new());
        self.merge(kept, &fresh);
    }

    /// Moves the edges whose ends are both live to the front of the list, in order, and returns
    /// their number. The list keeps its length: the stale entries behind are room for
    /// [`Passes::merge`], which then needs no new entries filled first (a pass's collapses end
    /// more edges than they make).
    fn drop_dead_edges(&mut self) -> usize {
        let alive = &self.alive;
        let mut kept = 0;
        for i in 0..self.edges.len() {
            let e = self.edges[i];
            if alive[e.a as usize] && alive[e.b as usize] {
                self.edges[kept] = e;
                kept += 1;
            }
        }
        kept
    }

    /// Merges the sorted `fresh` edges with the list's first `old` (sorted) ones, from the back
    /// into room at the end: no second list. An old edge goes before a new one of the same cost:
    /// each new edge, last first, goes in after the old ones that cost more are moved up.
    fn merge(&mut self, old: usize, fresh: &[Edge]) {
        let total = old + fresh.len();
        if total <= self.edges.len() {
            self.edges.truncate(total);
        } else {
            self.edges.resize(total, Edge::default());
        }
        let (mut i, mut at) = (old, total);
        for &e in fresh.iter().rev() {
            while i > 0 && self.edges[i - 1].key > e.key {
                i -= 1;
                at -= 1;
                self.edges[at] = self.edges[i];
            }
            at -= 1;
            self.edges[at] = e;
        }
    }

    /// What the collapses leave for the hierarchy (the faces' corners as vertex ids again), all
    /// else freed.
    pub fn into_collapsed(self) -> Collapsed<'o> {
        let (mut collapsed, records) = self.into_parts();
        // The rest of the engine is gone: the records can be joined.
        collapsed.collapses = records.into_vec();
        collapsed
    }

    /// [`Passes::into_collapsed`] but for the collapse records, still in chunks; the rest of
    /// the engine is freed on return.
    fn into_parts(self) -> (Collapsed<'o>, Chunks<Collapse>) {
        let mut faces = self.faces;
        for (t, &alive) in faces.iter_mut().zip(&self.face_alive) {
            *t = if alive {
                t.map(|s| self.owner[s as usize])
            } else {
                [NONE; 3]
            };
        }
        let collapsed = Collapsed {
            heap_pushes: self.evaluations,
            opts: self.opts,
            pos: self.pos,
            color: self.color,
            faces,
            face_alive: self.face_alive,
            collapses: Vec::new(),
            fans: self.fans,
            fan_ends: self.fan_ends,
        };
        (collapsed, self.collapses)
    }

    /// Brings the filing up to date after a pass: only the collapses' wings lost faces (each
    /// collapse filed its new vertex's anew), so each of those drops its dead faces in place;
    /// once the garbage left behind outgrows the live entries, everything is filed again.
    fn refile(&mut self) {
        if self.around.len() > 6 * self.faces_alive + 1024 {
            self.thinned.clear();
            self.file_faces();
            return;
        }
        for &s in &self.thinned {
            let s = s as usize;
            if !self.alive[self.owner[s] as usize] {
                continue;
            }
            let mut kept = self.first[s];
            for i in self.first[s]..self.end[s] {
                let f = self.around[i as usize];
                self.around[kept as usize] = f;
                kept += u32::from(self.face_alive[f as usize]);
            }
            self.end[s] = kept;
        }
        self.thinned.clear();
    }

    /// Files every live face under its corners, in face order: a counting sort over the live
    /// slots only (their number falls with every pass; the slots do not).
    fn file_faces(&mut self) {
        let face_alive = &self.face_alive;
        self.live.retain(|&f| face_alive[f as usize]);
        let (owner, alive) = (&self.owner, &self.alive);
        self.live_slots
            .retain(|&s| alive[owner[s as usize] as usize]);
        let (first, end) = (&mut self.first, &mut self.end);
        for &s in &self.live_slots {
            end[s as usize] = 0;
        }
        for &f in &self.live {
            for s in self.faces[f as usize] {
                end[s as usize] += 1;
            }
        }
        let mut at = 0;
        for &s in &self.live_slots {
            let s = s as usize;
            first[s] = at;
            at += end[s];
            // `end` runs from the first as the slot fills.
            end[s] = first[s];
        }
        self.around.clear();
        self.around.resize(at as usize, 0);
        for &f in &self.live {
            for s in self.faces[f as usize] {
                let at = &mut end[s as usize];
                self.around[*at as usize] = f;
                *at += 1;
            }
        }
    }

    /// The faces around slot `s` as filed at the pass's start.
    fn faces_of(&self, s: u32) -> &[u32] {
        let s = s as usize;
        &self.around[self.first[s] as usize..self.end[s] as usize]
    }

    fn face_normal(&self, t: [u32; 3]) -> Vec3d {
        let [a, b, c] = t.map(|s| self.pos.get(self.owner[s as usize]));
        cross(sub(b, a), sub(c, a))
    }

    /// Vertex `v`'s neighbours (vertex ids), in any order, into `ring`.
    fn ring(&mut self, v: u32, ring: &mut Vec<u32>) {
        let s = self.slot[v as usize];
        let tag = self.next_stamp();
        self.stamp[s as usize] = tag;
        ring.clear();
        for i in self.first[s as usize]..self.end[s as usize] {
            let f = self.around[i as usize];
            for x in self.faces[f as usize] {
                if self.stamp[x as usize] != tag {
                    self.stamp[x as usize] = tag;
                    ring.push(self.owner[x as usize]);
                }
            }
        }
    }

    /// A stamp no slot carries yet.
    fn next_stamp(&mut self) -> u32 {
        self.stamped = self.stamped.wrapping_add(1);
        if self.stamped == 0 {
            self.stamp.iter_mut().for_each(|t| *t = 0);
            self.stamped = 1;
        }
        self.stamped
    }

    /// Whether slot `s` is on a border, and its number of neighbours. In a manifold fan every
    /// neighbour follows `s` in one triangle and precedes it in another, but for the two ends
    /// of an open fan: the exclusive or of all of them is zero exactly when the fan is closed.
    fn fan(&self, s: u32) -> (bool, usize) {
        let faces = self.faces_of(s);
        let mut x = 0;
        for &f in faces {
            if let Some((next, prev)) = after(self.faces[f as usize], s) {
                x ^= next ^ prev;
            }
        }
        fan_of(x, faces.len())
    }

    /// The two ends of slot `s`'s open fan (`s -> first` and `last -> s` have no twin).
    fn fan_ends(&self, s: u32) -> [u32; 2] {
        let faces = self.faces_of(s);
        let mut ends = [NONE; 2];
        for &f in faces {
            if let Some((next, prev)) = after(self.faces[f as usize], s) {
                let twin = |x: u32, first: bool| {
                    faces.iter().any(|&g| {
                        after(self.faces[g as usize], s).is_some_and(|(n, p)| {
                            if first {
                                p == x
                            } else {
                                n == x
                            }
                        })
                    })
                };
                if !twin(next, true) {
                    ends[0] = next;
                }
                if !twin(prev, false) {
                    ends[1] = prev;
                }
            }
        }
        ends
    }

    /// The faces with directed edge `a -> b` and `b -> a` (slots), as (third corner of each or
    /// NONE, number of faces on the edge).
    #[inline]
    fn edge_faces(&self, a: u32, b: u32) -> ([u32; 2], usize) {
        edge_wings(&self.faces, self.faces_of(a), a, b)
    }

    /// The edge `a-b` (vertex ids, `a < b`) with its cost.
    fn edge(&mut self, a: u32, b: u32) -> Edge {
        let (_, cost) = self.evaluate(a, b);
        self.evaluations += 1;
        Edge {
            key: cost_key(cost),
            a,
            b,
            tried: 0,
        }
    }

    /// Where the merged vertex goes and what the collapse costs (the heap engine's rules).
    /// Inlined (as are the shared rules it calls): out of line, the calls cost the bunny's
    /// balanced build 8 million more instructions, 1.4%.
    #[inline(always)]
    fn evaluate(&self, a: u32, b: u32) -> (Vec3d, f64) {
        let (pa, pb) = (self.pos.get(a), self.pos.get(b));
        let (sa, sb) = (self.slot[a as usize], self.slot[b as usize]);
        let q = self.quadric[sa as usize].add(&self.quadric[sb as usize]);
        let v = placement(self.opts, &q, pa, pb);
        let colors = || [color_of(&self.color, a), color_of(&self.color, b)];
        let cost = cost_at(self.opts, &q, v, [pa, pb], colors, self.surface.as_ref());
        (v, cost)
    }

    /// Whether collapsing the edge `a-b` (vertex ids) keeps the mesh a manifold of the same
    /// topology with no flipped or degenerate triangle (the heap engine's tests), or waits for
    /// the next pass.
    fn judge(&mut self, ia: u32, ib: u32) -> Verdict {
        let (a, b) = (self.slot[ia as usize], self.slot[ib as usize]);
        let (wings, count) = self.edge_faces(a, b);
        if count == 0 {
            return Verdict::Illegal;
        }
        let k = self.pass;
        if wings
            .iter()
            .any(|&w| w != NONE && self.mark[w as usize] == k)
        {
            return Verdict::Blocked;
        }
        let (v, _) = self.evaluate(ia, ib);
        if self.legal(a, b, v, wings, count) {
            Verdict::Legal(v, wings)
        } else {
            Verdict::Illegal
        }
    }

    fn legal(&mut self, a: u32, b: u32, v: Vec3d, wings: [u32; 2], count: usize) -> bool {
        // Link condition: the common neighbours are exactly the wings. The neighbours of `a`
        // are stamped, then those of `b` looked up, each counted once.
        let tag = self.next_stamp();
        let seen = self.next_stamp();
        // The same walks find whether each end's fan is open, as [`Passes::fan`] does.
        let (mut xa, mut xb) = (0, 0);
        for i in self.first[a as usize]..self.end[a as usize] {
            let f = self.around[i as usize];
            let t = self.faces[f as usize];
            if let Some((next, prev)) = after(t, a) {
                xa ^= next ^ prev;
            }
            for x in t {
                self.stamp[x as usize] = tag;
            }
        }
        let w = wings.map(|x| (x != NONE).then_some(x));
        let mut common = 0;
        for i in self.first[b as usize]..self.end[b as usize] {
            let f = self.around[i as usize];
            let t = self.faces[f as usize];
            if let Some((next, prev)) = after(t, b) {
                xb ^= next ^ prev;
            }
            for x in t {
                if x == a || x == b || self.stamp[x as usize] != tag {
                    continue;
                }
                if !w.contains(&Some(x)) {
                    return false;
                }
                self.stamp[x as usize] = seen;
                common += 1;
            }
        }
        if common != w.iter().flatten().count() || (w[0].is_some() && w[0] == w[1]) {
            return false;
        }
        let edge_on_border = count == 1;
        let (ba, ra) = fan_of(xa, self.faces_of(a).len());
        let (bb, rb) = fan_of(xb, self.faces_of(b).len());
        if ba && bb && !edge_on_border {
            return false; // would pinch two borders (or a border and itself) together
        }
        if edge_on_border {
            // A border loop of three edges would close up.
            let outer =
                |s: u32, other: u32| self.fan_ends(s).map(|x| if x == other { NONE } else { x });
            let (oa, ob) = (outer(a, b), outer(b, a));
            if oa.iter().any(|&x| x != NONE && ob.contains(&x)) {
                return false;
            }
        }
        // Degrees: the merged vertex and the wings keep enough neighbours.
        let degree_p = ra + rb - 2 - common;
        if degree_p < if ba || bb { 2 } else { 3 } {
            return false;
        }
        for x in w.into_iter().flatten() {
            let (border, ring) = self.fan(x);
            if ring < if border { 3 } else { 4 } {
                return false;
            }
        }
        // No flipped or collapsed triangle.
        for s in [a, b] {
            for &f in self.faces_of(s) {
                let t = self.faces[f as usize];
                if t.contains(&a) && t.contains(&b) {
                    continue;
                }
                let at = |i: u32| self.pos.get(self.owner[i as usize]);
                let moved = t.map(|i| if i == s { v } else { at(i) });
                if !stays_up(t.map(at), moved) {
                    return false;
                }
            }
        }
        true
    }

    /// Collapses `a-b` (vertex ids) into a new vertex at `v` and marks the region it touched;
    /// `wings` are the third corners of the faces with directed edges `a -> b` and `b -> a`.
    fn collapse(&mut self, a: u32, b: u32, v: Vec3d, wings: [u32; 2]) {
        let (sa, sb) = (self.slot[a as usize], self.slot[b as usize]);
        // Orient so that triangle (children[0], children[1], wings[0]) exists.
        let (children, wings) = if wings[0] != NONE {
            ([sa, sb], wings)
        } else {
            ([sb, sa], [wings[1], wings[0]])
        };
        let id = |s: u32| {
            if s == NONE {
                NONE
            } else {
                self.owner[s as usize]
            }
        };
        let (children_ids, wing_ids) = (children.map(id), wings.map(id));
        let p = self.pos.len() as u32;
        let (ia, ib) = (a as usize, b as usize);
        self.pos.push(v);
        let qa = sa as usize;
        let ends = [(a, qa, self.pos.get(a)), (b, sb as usize, self.pos.get(b))];
        merge_sums(
            self.opts,
            &mut self.quadric,
            &mut self.area,
            &mut self.color,
            ends,
            v,
        );
        self.slot.push(sa);
        self.owner[qa] = p;
        // One walk round each end (a's list, then b's, as filed: neither slot is filed again
        // before the next pass) marks the region, drops the faces on the edge and files p's
        // other faces anew at the end (the segments of a and b become garbage).
        // The split's records come off the same walks.
        let from = self.around.len() as u32;
        let mut split = Split::new(children, wings);
        // (Each end's number a constant in its walk.)
        if children[0] == sa {
            self.take_faces::<0>(sa, [sa, sb], &mut split);
            self.take_faces::<1>(sb, [sa, sb], &mut split);
        } else {
            self.take_faces::<1>(sa, [sa, sb], &mut split);
            self.take_faces::<0>(sb, [sa, sb], &mut split);
        }
        let record = Collapse {
            parent: p,
            children: children_ids,
            wings: wing_ids,
            faces: split.on_edge,
            neighbours: split.neighbours,
        };
        // No earlier collapse of the pass marked a wing, nor will a later one: each is listed once.
        self.thinned.extend(wings.iter().filter(|&&w| w != NONE));
        if self.opts.bound != ErrorBound::Offset {
            // The faces around p in face order, as the heap engine lists them.
            let mut fan: Vec<u32> = self.faces_of(sa).to_vec();
            fan.extend_from_slice(self.faces_of(sb));
            fan.sort_unstable();
            fan.dedup();
            let owner = &self.owner;
            for f in fan {
                if self.face_alive[f as usize] {
                    let t = self.faces[f as usize];
                    self.fans.push(t.map(|s| owner[s as usize]));
                }
            }
            self.fan_ends.push(self.fans.len() as u32);
        }
        self.first[qa] = from;
        self.end[qa] = self.around.len() as u32;
        self.alive[ia] = false;
        self.alive[ib] = false;
        self.alive.push(true);
        self.alive_count -= 1;
        self.collapses.push(record);
    }

    /// The walk round end `s` of collapse `[sa, sb]`: shows each face to `split` as round its
    /// end `END`, marks the face's corners, drops the face if on the edge (filed under both
    /// ends: on the first meeting) and else renames `sb` to `sa` in it and files it for the new
    /// vertex, after those already filed.
    #[inline(always)]
    fn take_faces<const END: usize>(&mut self, s: u32, [sa, sb]: [u32; 2], split: &mut Split) {
        let k = self.pass;
        for i in self.first[s as usize]..self.end[s as usize] {
            let f = self.around[i as usize];
            let t = self.faces[f as usize];
            split.see(END, f, t);
            for x in t {
                self.mark[x as usize] = k;
            }
            if t.contains(&sa) && t.contains(&sb) {
                if self.face_alive[f as usize] {
                    self.face_alive[f as usize] = false;
                    self.faces_alive -= 1;
                }
            } else {
                if s == sb {
                    self.faces[f as usize] = t.map(|x| if x == sb { sa } else { x });
                }
                self.around.push(f);
            }
        }
    }
}

/// [`Passes::fan`]'s answer from the exclusive or `x` of every neighbour a fan's `faces` have
/// after and before its vertex: whether it is open, and its number of neighbours.
fn fan_of(x: u32, faces: usize) -> (bool, usize) {
    (x != 0, faces + usize::from(x != 0))
}

/// Sorts `edges` by cost, keeping the order they came in among equal costs: a radix sort on the
/// cost's bits, a byte at a time (each pass stable), or an insertion sort of a few. `scratch` is
/// working room: every entry it holds is written before it is read, so it is filled once, not
/// once a digit.
fn sort_by_cost(edges: &mut Vec<Edge>, scratch: &mut Vec<Edge>) {
    if edges.len() < 64 {
        for i in 1..edges.len() {
            let e = edges[i];
            let mut j = i;
            while j > 0 && edges[j - 1].key > e.key {
                edges[j] = edges[j - 1];
                j -= 1;
            }
            edges[j] = e;
        }
        return;
    }
    let counts = digit_counts(edges);
    scratch.resize(edges.len(), Edge::default());
    for (byte, count) in counts.iter().enumerate() {
        if count.contains(&edges.len()) {
            continue; // every edge has this digit: nothing moves
        }
        let mut start = [0usize; 256];
        let mut at = 0;
        for (s, &c) in start.iter_mut().zip(count) {
            *s = at;
            at += c;
        }
        for e in edges.iter() {
            let d = &mut start[digit(e, byte)];
            // `start[d]` stays below the number of edges of digit `d` or less.
            if let Some(slot) = scratch.get_mut(*d) {
                *slot = *e;
            }
            *d += 1;
        }
        core::mem::swap(edges, scratch);
    }
}

/// Byte `byte` of an edge's cost key.
#[inline(always)]
fn digit(e: &Edge, byte: usize) -> usize {
    (e.key >> (8 * byte)) as usize & 0xff
}

/// How many edges have each value of each byte of their cost key, counted in one walk.
fn digit_counts(edges: &[Edge]) -> [[usize; 256]; 4] {
    let mut counts = [[0usize; 256]; 4];
    for e in edges {
        for (byte, count) in counts.iter_mut().enumerate() {
            count[digit(e, byte)] += 1;
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorting_by_cost_keeps_the_measuring_order_among_equal_costs() {
        // A small generator (xorshift), so the test needs no dependency.
        let mut x = 0x2545_F491u32;
        let mut next = |m: u32| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x % m
        };
        for n in [0usize, 1, 63, 64, 500, 5000] {
            // Few distinct costs, so that many tie; some differ only in one byte. The measuring
            // order is in `a`.
            let mut edges: Vec<Edge> = (0..n as u32)
                .map(|a| Edge {
                    key: [0, 1, 0x3f80_0000, 0x7f7f_ffff, 0x0100_0000][next(5) as usize] + next(3),
                    a,
                    b: n as u32 + next(100),
                    tried: 0,
                })
                .collect();
            let mut expected = edges.clone();
            expected.sort_by_key(|e| e.key); // stable
            sort_by_cost(&mut edges, &mut Vec::new());
            assert_eq!(edges, expected, "{n}");
        }
    }
}
