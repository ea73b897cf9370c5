// Shared by every target: parse the input as one format (gzip-wrapped or not) and check the
// invariants of whatever comes back. Inflating is capped so the fuzzer's memory stays bounded.

macro_rules! fuzz_format {
    ($format:expr) => {
        libfuzzer_sys::fuzz_target!(|data: &[u8]| {
            let options = lineao_tracts::LoadOptions { max_inflated_bytes: Some(16 << 20) };
            if let Ok(t) = lineao_tracts::parse_as(data, $format, &options) {
                t.validate().expect("a parser returned an inconsistent tractogram");
            }
        });
    };
}
