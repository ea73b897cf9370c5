// The pieces the cull found visible (`lineao::passes::cull`), as the culled lines and tubes
// draw them: cluster << 6 | left << 4 | level << 2 | piece, where piece p of a cluster is its
// strip's segments 8p .. 8p + 7 (points 8p ..= 8p + 8, or to its end), drawn keeping every
// 2^level-th point of it and its last; `left` is 0 but in the frozen cull's picture of what it
// left out (1 outside the view, 2 behind what it drew: `cull.wgsl`'s `list_all`). A draw of
// full pieces reads its list from the front, one of coarse pieces (level > 0) from the back.
// Bind group 2 of their pipelines.
#import shared/clusters.wgsl

@group(2) @binding(0) var<storage, read> visible_pieces: array<u32>;

// A listed piece: its cluster, its first point in the cluster's strip, how many it spans, the
// stride of the points it keeps, and why the cull left it out (0: it did not).
struct VisiblePiece {
    cluster: Cluster,
    first: u32,
    points: u32,
    stride: u32,
    left: u32,
}

// The piece of slot `slot` of the list of full (or `coarse`) pieces. Slots past the listed
// pieces hold NO_PIECE (the cull pads the last instance), which spans no point: nothing drawn.
fn visible_piece(slot: u32, coarse: bool) -> VisiblePiece {
    let length = arrayLength(&visible_pieces);
    var entry = NO_PIECE;
    if slot < length {
        entry = visible_pieces[select(slot, length - 1u - slot, coarse)];
    }
    return listed_piece(entry);
}

// The piece a list entry names (NO_PIECE: one that spans no point).
fn listed_piece(entry: u32) -> VisiblePiece {
    if entry == NO_PIECE {
        return VisiblePiece(clusters[0], 0u, 0u, 1u, 0u);
    }
    let c = clusters[entry >> 6u];
    let first = (entry & 3u) * PIECE_SEGMENTS;
    let points = min(drawn_points(c) - first, PIECE_SEGMENTS + 1u);
    return VisiblePiece(c, first, points, 1u << ((entry >> 2u) & 3u), (entry >> 4u) & 3u);
}

// How many points a piece keeps: every stride-th and its last.
fn kept_points(piece: VisiblePiece) -> u32 {
    if piece.points < 2u {
        return piece.points;
    }
    return (piece.points + piece.stride - 2u) / piece.stride + 1u;
}

// The strip point of the piece's k-th kept point.
fn kept_point(piece: VisiblePiece, k: u32) -> u32 {
    return piece.first + min(k * piece.stride, piece.points - 1u);
}
