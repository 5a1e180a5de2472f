//! Hostile bytes into the semi-regular loader and the wavelet cut: an error, or a view that a
//! cut flies with its invariants holding; never a panic.
//!
//! Each input is tried as it is and with its checksum recomputed, so that mutations reach the
//! structural checks behind the CRC.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vdlod_core::adapt::Budget;
use vdlod_core::format::crc32;
use vdlod_core::policy::{QRefine, View};
use vdlod_core::wavelet::format::{CRC_OFFSET, HEADER_SIZE};
use vdlod_core::wavelet::{SemiRegularView, WaveletCut};

fn check(data: &[u8]) {
    let Ok(view) = SemiRegularView::parse(data) else {
        return;
    };
    let mut cut = WaveletCut::<64, 1024, 600, 128>::boxed();
    if cut.reset(&view).is_err() {
        return;
    }
    let mut scratch = [[0u32; 2]; 3 * 1024];
    for i in 0..4 {
        let a = i as f32;
        let eye = [3.0 * a.cos(), 0.5 - 0.2 * a, 3.0 * a.sin()];
        let v = View::look_at(eye, [0.0; 3], [0.0, 1.0, 0.0], 1.0, 1.3, 240.0);
        let budget = Budget {
            max_triangles: 60 + 400 * (i % 2),
            ..Budget::default()
        };
        cut.adapt(&view, &v, &QRefine::new(0.5 + a), &budget);
        assert!(cut.check(&view, false, &mut scratch).is_ok());
    }
}

fuzz_target!(|data: &[u8]| {
    check(data);
    if data.len() >= HEADER_SIZE {
        let mut sealed = data.to_vec();
        let crc = crc32(&sealed[HEADER_SIZE..]);
        sealed[CRC_OFFSET..CRC_OFFSET + 4].copy_from_slice(&crc.to_le_bytes());
        check(&sealed);
    }
});
