//! The semi-regular format against hostile bytes: corrupted, truncated or forged files give an
//! error, never a panic, and whatever parses can be flown by a wavelet cut without a panic, its
//! invariants holding.

use std::sync::OnceLock;

use proptest::prelude::*;
use vdlod_core::adapt::Budget;
use vdlod_core::format::crc32;
use vdlod_core::policy::{QRefine, View};
use vdlod_core::wavelet::build::{interpolate, SemiRegular};
use vdlod_core::wavelet::format::{CRC_OFFSET, HEADER_SIZE, VERSION};
use vdlod_core::wavelet::{SemiRegularError, SemiRegularView, WaveletCut};

fn sphere_bytes() -> &'static [u8] {
    static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
    BYTES.get_or_init(|| SemiRegular::sphere(2).unwrap().to_bytes().unwrap())
}

/// An open mesh: a square of two faces, subdivided twice, so borders are covered too.
fn square() -> SemiRegular {
    let base = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let faces = [[0, 1, 2], [0, 2, 3]];
    let n = 4.0;
    SemiRegular::from_fn(&base, &faces, 2, |f, w| {
        let p = interpolate(faces[f as usize].map(|v| base[v as usize]), w, n);
        [p[0], p[1], 0.1 * (p[0] * 7.0).sin() * (p[1] * 5.0).cos()]
    })
    .unwrap()
}

fn square_bytes() -> Vec<u8> {
    square().to_bytes().unwrap()
}

/// The square as a height field (z up).
fn heights_bytes() -> Vec<u8> {
    square().to_height_bytes(2).unwrap()
}

/// Flies a small cut over whatever parsed; its invariants hold after every frame (on a mesh
/// with borders, an edge may have one side).
fn fly(view: &SemiRegularView<'_>) {
    let mut cut = WaveletCut::<64, 1024, 600, 128>::boxed();
    if cut.reset(view).is_err() {
        return;
    }
    let mut scratch = vec![[0u32; 2]; 3 * 1024];
    for i in 0..6 {
        let a = i as f32;
        let eye = [3.0 * a.cos(), 0.5 - 0.2 * a, 3.0 * a.sin() - 0.5 * a];
        let v = View::look_at(eye, [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.3, 240.0);
        let budget = Budget {
            max_triangles: 60 + 400 * (i % 2),
            ..Budget::default()
        };
        let stats = cut.adapt(view, &v, &QRefine::new(0.5 + a), &budget);
        assert!(stats.triangles <= budget.max_triangles.max(view.counts().base_faces));
        cut.check(view, false, &mut scratch).unwrap();
    }
}

fn reseal(bytes: &mut [u8]) {
    if bytes.len() >= HEADER_SIZE {
        let crc = crc32(&bytes[HEADER_SIZE..]);
        bytes[CRC_OFFSET..CRC_OFFSET + 4].copy_from_slice(&crc.to_le_bytes());
    }
}

#[test]
fn valid_files_parse_and_fly() {
    let view = SemiRegularView::parse(sphere_bytes()).unwrap();
    assert_eq!(view.wavelets(), 12 * 3 + 8 * 3);
    fly(&view);
    let square = square_bytes();
    let view = SemiRegularView::parse(&square).unwrap();
    assert_eq!(view.counts().base_edges, 5);
    fly(&view);
    let heights = heights_bytes();
    let view = SemiRegularView::parse(&heights).unwrap();
    assert!(view.is_height_field());
    fly(&view);
}

/// The `semiregular` fuzz target starts from `fuzz/seeds/semiregular/sphere2.vdw`
/// (`vdlod-demo sphere --levels 2`): it must stay a valid file of this format version, or the
/// fuzzer would spend its runs on the version check.
#[test]
fn the_fuzz_seed_is_a_valid_file() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fuzz/seeds/semiregular/sphere2.vdw"
    );
    let bytes = std::fs::read(path).unwrap();
    match SemiRegularView::parse(&bytes) {
        Ok(view) => fly(&view),
        Err(e) => panic!("{path}: {e} (rebuild the seed: fuzz/README.md)"),
    }
}

#[test]
fn a_height_fields_header_is_checked() {
    let good = heights_bytes();
    let forge = |at: usize, value: u8| {
        let mut bytes = good.clone();
        bytes[at] = value;
        reseal(&mut bytes);
        SemiRegularView::parse(&bytes).err()
    };
    // Up axis 3, no fine level, more fine levels than levels, a reserved byte set.
    for (at, value) in [(56, 3), (57, 0), (57, 3), (58, 1)] {
        assert!(
            matches!(forge(at, value), Some(SemiRegularError::BadCounts(_))),
            "byte {at} = {value}"
        );
    }
    // Hoppe's bounds have no place in a height field.
    assert!(matches!(
        forge(6, 4 | 2),
        Some(SemiRegularError::BadCounts(_))
    ));
    // Fewer fine levels mean more coarse records: the sizes no longer match.
    assert!(matches!(
        forge(57, 1),
        Some(SemiRegularError::Truncated { .. } | SemiRegularError::TrailingBytes { .. })
    ));
}

#[test]
fn each_kind_of_damage_has_its_own_error() {
    let good = sphere_bytes();
    let mut flipped = good.to_vec();
    flipped[HEADER_SIZE + 3] ^= 1;
    assert!(matches!(
        SemiRegularView::parse(&flipped),
        Err(SemiRegularError::Checksum { .. })
    ));
    assert!(matches!(
        SemiRegularView::parse(&good[..good.len() - 1]),
        Err(SemiRegularError::Truncated { .. })
    ));
    let mut newer = good.to_vec();
    newer[4..6].copy_from_slice(&(VERSION + 1).to_le_bytes());
    let e = SemiRegularView::parse(&newer).unwrap_err();
    assert_eq!(e, SemiRegularError::UnsupportedVersion(VERSION + 1));
    assert!(e.to_string().contains("version"));
    // A face whose across link points at itself, checksum forged: a face error.
    let mut forged = good.to_vec();
    forged[HEADER_SIZE + 24..HEADER_SIZE + 28].copy_from_slice(&0u32.to_le_bytes());
    reseal(&mut forged);
    let e = SemiRegularView::parse(&forged).unwrap_err();
    assert!(
        matches!(e, SemiRegularError::BadFace { face: 0, .. }),
        "{e}"
    );
    // Levels beyond the limit.
    let mut deep = good.to_vec();
    deep[8..12].copy_from_slice(&13u32.to_le_bytes());
    reseal(&mut deep);
    assert!(matches!(
        SemiRegularView::parse(&deep),
        Err(SemiRegularError::BadCounts(_))
    ));
    // A hierarchy file is not a semi-regular one.
    let hierarchy = [b"VDLH".as_slice(), &[3, 0], &[b'.'; 58]].concat();
    assert_eq!(
        SemiRegularView::parse(&hierarchy).err(),
        Some(SemiRegularError::BadMagic)
    );
}

/// A base vertex that no face uses (here the square's face 0 names corner 3 instead of 1, a
/// case the property test below once drew) is not counted among the mesh's vertices.
#[test]
fn an_unused_base_vertex_is_not_counted() {
    for mut bytes in [square_bytes(), heights_bytes()] {
        let corner = HEADER_SIZE + 4;
        assert_eq!(bytes[corner], 1);
        bytes[corner] = 3;
        reseal(&mut bytes);
        let view = SemiRegularView::parse(&bytes).unwrap();
        let mut cut = WaveletCut::<64, 1024, 600, 128>::boxed();
        cut.reset(&view).unwrap();
        assert_eq!(cut.live_vertices(), 3);
        cut.check(&view, false, &mut vec![[0u32; 2]; 3 * 1024])
            .unwrap();
        fly(&view);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn corrupted_files_are_rejected_or_flyable(
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        resealed in any::<bool>(),
        kind in 0..3u8,
    ) {
        let mut bytes = match kind {
            0 => sphere_bytes().to_vec(),
            1 => square_bytes(),
            _ => heights_bytes(),
        };
        for (at, value) in &edits {
            let i = at.index(bytes.len());
            bytes[i] = *value;
        }
        if resealed {
            reseal(&mut bytes);
        }
        if let Ok(view) = SemiRegularView::parse(&bytes) {
            fly(&view);
        }
    }

    #[test]
    fn truncated_files_are_rejected(cut in any::<prop::sample::Index>()) {
        let bytes = sphere_bytes();
        let n = cut.index(bytes.len());
        prop_assert!(SemiRegularView::parse(&bytes[..n]).is_err());
    }

    #[test]
    fn random_bytes_behind_a_valid_header_are_rejected_or_flyable(
        body in prop::collection::vec(any::<u8>(), 0..1024),
        counts in [1u32..4, 0u32..12, 0u32..8, 0u32..16],
    ) {
        let mut bytes = sphere_bytes()[..HEADER_SIZE].to_vec();
        for (k, c) in counts.iter().enumerate() {
            bytes[8 + 4 * k..12 + 4 * k].copy_from_slice(&c.to_le_bytes());
        }
        bytes.extend_from_slice(&body);
        reseal(&mut bytes);
        if let Ok(view) = SemiRegularView::parse(&bytes) {
            fly(&view);
        }
    }
}
