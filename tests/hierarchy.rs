//! The hierarchy builder on the fixtures: exact round trips, topology kept, forest depth.

mod common;

use common::{fixture, sorted, topology};
use vdlod_core::build::{build, BuildOptions, Cost, Hierarchy, InputMesh, NONE};
use vdlod_demo::mesh::{load_obj_bytes, IndexedMesh, BUNNY_NAME, BUNNY_OBJ, COW_NAME, COW_OBJ};

fn hierarchy(mesh: &IndexedMesh, opts: BuildOptions) -> Hierarchy {
    let input = InputMesh {
        positions: &mesh.positions,
        colors: mesh.colors.as_deref(),
        triangles: &mesh.triangles,
    };
    build(&input, &opts, &mut |_| {}).expect("fixture builds")
}

fn check_round_trip(mesh: &IndexedMesh, opts: BuildOptions) -> Hierarchy {
    let h = hierarchy(mesh, opts);
    assert_eq!(sorted(&h.refine_all()), sorted(&mesh.triangles), "{opts:?}");
    assert_eq!(
        sorted(&h.collapse_all(&mesh.triangles)),
        sorted(&h.base_triangles),
        "{opts:?}"
    );
    assert_eq!(
        topology(&h.base_triangles),
        topology(&mesh.triangles),
        "{opts:?}"
    );
    h
}

#[test]
fn cow_round_trips_with_every_cost() {
    let cow = load_obj_bytes(COW_NAME, COW_OBJ).unwrap();
    for cost in [Cost::Quadric, Cost::ShortestEdge, Cost::Color] {
        let h = check_round_trip(
            &cow,
            BuildOptions {
                cost,
                ..BuildOptions::default()
            },
        );
        assert!(
            h.base_triangles.len() < 100,
            "{cost:?}: {}",
            h.base_triangles.len()
        );
    }
}

#[test]
fn open_and_higher_genus_meshes_keep_their_topology() {
    let head = fixture("head.obj");
    assert_eq!(topology(&head.triangles), (-1, 3)); // genus 0 with three holes
    let elk = fixture("elk.obj");
    assert_eq!(topology(&elk.triangles), (0, 0)); // genus 1
    for mesh in [&head, &elk] {
        for cost in [Cost::Quadric, Cost::ShortestEdge] {
            for balanced in [false, true] {
                check_round_trip(
                    mesh,
                    BuildOptions {
                        cost,
                        balanced,
                        ..BuildOptions::default()
                    },
                );
            }
        }
    }
}

/// A CAD model with sharp creases: many collapses are illegal (they would flip triangles), which
/// once made retried edges pile up exponentially. The heap work must stay linear.
#[test]
fn fandisk_builds_with_linear_heap_work() {
    let fandisk = fixture("fandisk.obj");
    let h = check_round_trip(&fandisk, BuildOptions::default());
    let edges = fandisk.triangles.len() as u64 * 3 / 2;
    // About 3.5 pushes an edge are measured; the runaway reached millions within seconds.
    assert!(
        h.heap_pushes <= 6 * edges,
        "{} pushes for {edges} edges",
        h.heap_pushes
    );
}

#[test]
fn bunny_round_trips_keeps_topology_and_is_shallow_when_balanced() {
    let bunny = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).unwrap();
    assert_eq!(topology(&bunny.triangles), (2, 0)); // closed, genus 0
    let h = check_round_trip(
        &bunny,
        BuildOptions {
            balanced: true,
            ..BuildOptions::default()
        },
    );
    let (max, mean) = h.depth_stats();
    let log2n = (bunny.positions.len() as f64).log2();
    // Balanced forests: depth within a small multiple of log2(n) (15.2 for the bunny).
    assert!(
        f64::from(max) <= 3.0 * log2n,
        "max depth {max}, mean {mean:.1}"
    );
    assert!(h.roots().all(|r| h.nodes[r as usize].parent == NONE));
}
