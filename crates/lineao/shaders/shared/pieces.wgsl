// The pieces the cull found visible (`lineao::passes::cull`), as the culled lines and tubes
// draw them: cluster << 2 | piece, where piece p of a cluster is its strip's segments
// 8p .. 8p + 7 (points 8p ..= 8p + 8, or to its end). Bind group 2 of their pipelines.
#import shared/clusters.wgsl

@group(2) @binding(0) var<storage, read> visible_pieces: array<u32>;

// A listed piece: its cluster, its first point in the cluster's strip and how many it draws.
struct VisiblePiece {
    cluster: Cluster,
    first: u32,
    points: u32,
}

// The piece of slot `slot`. Slots past the listed pieces hold pieces listed before (or
// cluster 0's first): drawing more of the lines than the visible ones leaves the same G-buffer.
fn visible_piece(slot: u32) -> VisiblePiece {
    let entry = visible_pieces[min(slot, arrayLength(&visible_pieces) - 1u)];
    let c = clusters[entry >> 2u];
    let first = (entry & 3u) * PIECE_SEGMENTS;
    return VisiblePiece(c, first, min(drawn_points(c) - first, PIECE_SEGMENTS + 1u));
}
