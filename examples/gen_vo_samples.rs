//! Writes `crates/lineao/src/sample_sets/tables.rs`: the VO disk sample sets (Loos & Sloan
//! §4.5) for every count in `VO_SAMPLE_COUNTS`, from `lineao::sample_sets`'s generator.
//! Run `cargo run --release --example gen_vo_samples`.

use std::fmt::Write;

use lineao::sample_sets::{VO_SAMPLE_COUNTS, generate_vo_disk_samples};

fn main() {
    let mut out = String::from(
        "//! Written by `cargo run --release --example gen_vo_samples`; do not edit.\n\n\
         /// (N, [(x, y, A_i); N]) for every count in `VO_SAMPLE_COUNTS`.\n\
         pub const VO_DISK_SAMPLES: &[(u32, &[[f32; 3]])] = &[\n",
    );
    for n in VO_SAMPLE_COUNTS {
        writeln!(out, "    ({n}, &[").unwrap();
        for [x, y, a] in generate_vo_disk_samples(n) {
            writeln!(out, "        [{x:?}, {y:?}, {a:?}],").unwrap();
        }
        writeln!(out, "    ]),").unwrap();
    }
    out.push_str("];\n");
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/crates/lineao/src/sample_sets/tables.rs");
    std::fs::write(path, out).unwrap();
    println!("wrote {path}");
}
