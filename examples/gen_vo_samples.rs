//! Writes `crates/lineao/src/sample_sets/tables.rs`: the VO sample sets (Loos & Sloan §4.5) —
//! disk sets for every count in `VO_SAMPLE_COUNTS`, sphere (point) sets for every count in
//! `VO_SPHERE_SAMPLE_COUNTS` — from `lineao::sample_sets`'s generator.
//! Run `cargo run --release --example gen_vo_samples`.

use std::fmt::Write;

use lineao::sample_sets::{
    VO_SAMPLE_COUNTS, VO_SPHERE_SAMPLE_COUNTS, generate_vo_disk_samples, generate_vo_sphere_samples,
};

fn table(out: &mut String, doc: &str, name: &str, sets: impl Iterator<Item = (u32, Vec<[f32; 3]>)>) {
    writeln!(out, "/// {doc}\npub const {name}: &[(u32, &[[f32; 3]])] = &[").unwrap();
    for (n, set) in sets {
        writeln!(out, "    ({n}, &[").unwrap();
        for [a, b, c] in set {
            writeln!(out, "        [{a:?}, {b:?}, {c:?}],").unwrap();
        }
        writeln!(out, "    ]),").unwrap();
    }
    out.push_str("];\n");
}

fn main() {
    let mut out = String::from("//! Written by `cargo run --release --example gen_vo_samples`; do not edit.\n\n");
    table(
        &mut out,
        "(N, [(x, y, A_i); N]) for every count in `VO_SAMPLE_COUNTS`.",
        "VO_DISK_SAMPLES",
        VO_SAMPLE_COUNTS.into_iter().map(|n| (n, generate_vo_disk_samples(n))),
    );
    out.push('\n');
    table(
        &mut out,
        "(N, [(x, y, z); N]) for every count in `VO_SPHERE_SAMPLE_COUNTS`.",
        "VO_SPHERE_SAMPLES",
        VO_SPHERE_SAMPLE_COUNTS.into_iter().map(|n| (n, generate_vo_sphere_samples(n))),
    );
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/crates/lineao/src/sample_sets/tables.rs");
    std::fs::write(path, out).unwrap();
    println!("wrote {path}");
}
