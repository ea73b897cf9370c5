// Shared by every target: parse the input as one format (gzip-wrapped or not) and check the
// invariants of whatever comes back; then push the same bytes through the chunked decoder in
// pieces whose size the input picks, and check that every chunk is consistent and that, where
// both succeed on the same format, the chunks hold exactly the points of the whole parse.
// Inflating is capped so the fuzzer's memory stays bounded.

macro_rules! fuzz_format {
    ($format:expr) => {
        libfuzzer_sys::fuzz_target!(|data: &[u8]| {
            let options = lineao_tracts::LoadOptions { max_inflated_bytes: Some(16 << 20) };
            let whole = lineao_tracts::parse_as(data, $format, &options);
            if let Ok(t) = &whole {
                t.validate().expect("a parser returned an inconsistent tractogram");
            }
            let piece = 1 + data.first().map_or(0, |&b| b as usize * 37);
            let chunk_vertices = 1 + data.last().map_or(0, |&b| b as usize * 5);
            let mut points: Vec<[f32; 3]> = Vec::new();
            let mut sink = |chunk: lineao_tracts::Tractogram| {
                chunk.validate().expect("a chunk is an inconsistent tractogram");
                points.extend_from_slice(&chunk.positions);
                std::ops::ControlFlow::Continue(())
            };
            let name = format!("memory.{}", $format.name());
            let mut decoder = lineao_tracts::ChunkDecoder::new(&name, &options, None, chunk_vertices, &mut sink);
            let mut result = Ok(());
            for part in data.chunks(piece) {
                result = decoder.push(part);
                if result.is_err() {
                    break;
                }
            }
            let streamed = result.and_then(|()| decoder.finish());
            if let (Ok(t), Ok(s)) = (&whole, &streamed) {
                if s.format == Some($format) {
                    let same = points.len() == t.positions.len()
                        && points.iter().zip(&t.positions).all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits));
                    assert!(same, "the chunks hold other points than the whole parse");
                }
            }
        });
    };
}
