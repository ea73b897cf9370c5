#![no_main]
include!("common.rs");
fuzz_format!(lineao_tracts::Format::Vtp);
