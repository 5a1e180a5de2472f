use std::time::Instant;
use vdlod_core::adapt::Budget;
use vdlod_core::cut::Cut;
use vdlod_core::format::HierarchyView;
use vdlod_core::policy::QRefine;
use vdlod_demo::camera::peer_orbit;
use vdlod_demo::mesh::{load_obj_bytes, BUNNY_NAME, BUNNY_OBJ};
type BunnyCut = Cut<16384, 32768, 2048>;
fn minflt() -> u64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap();
    let rest = &s[s.rfind(')').unwrap() + 2..];
    rest.split_whitespace().nth(7).unwrap().parse().unwrap()
}
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let t: f32 = args[2].parse().unwrap();
    let touch = args.get(3).map(|s| s == "touch").unwrap_or(false);
    let bytes = std::fs::read(&args[1]).unwrap();
    let mesh = load_obj_bytes(BUNNY_NAME, BUNNY_OBJ).unwrap();
    let orbit = peer_orbit(&mesh.bounds(), 200, 640, 480);
    let h = HierarchyView::parse(&bytes).unwrap();
    let mut cut = BunnyCut::boxed();
    if touch {
        let p = (&mut *cut) as *mut BunnyCut as *mut u8;
        for i in (0..core::mem::size_of::<BunnyCut>()).step_by(4096) {
            unsafe { core::ptr::write_volatile(p.add(i), 0) };
        }
    }
    cut.reset(&h).unwrap();
    let f0 = minflt();
    let st = Instant::now();
    let s = cut.adapt(
        &h,
        &orbit.camera(0).view(),
        &QRefine::new(t),
        &Budget::default(),
    );
    let us = st.elapsed().as_secs_f64() * 1e6;
    let f1 = minflt();
    println!(
        "tol={t} touch={touch} tris={} first_us={us:.0} faults={}",
        s.triangles,
        f1 - f0
    );
}
