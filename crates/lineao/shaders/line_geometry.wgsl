// Compute passes over one page of clusters (`lineao::line_geometry`): the farthest point from
// a centre (the exact bounding sphere of a geometry streamed in) and every point decoded (what
// the tests hold against the input), one workgroup per cluster, one invocation per point; and
// the selection written into the records' flags, one invocation per record.
#import shared/clusters.wgsl

struct Params {
    center: vec3<f32>,
    clusters: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
// `farthest_point`: one word, the largest squared distance's bits (non-negative floats order as
// their bits). `decode_points`: a vec4 per point. `select_clusters`: the page's records, as
// words (`Cluster`: eight words, the flags the sixth).
@group(0) @binding(1) var<storage, read_write> output: array<atomic<u32>>;
// `select_clusters`: a bit per record, set where its streamline is selected out.
@group(0) @binding(2) var<storage, read> deselected: array<u32>;

// Workgroups per row of the dispatch (`lineao::line_geometry`'s ROW).
const ROW: u32 = 32768u;

fn page_point(group: vec3<u32>, k: u32) -> vec4<u32> {
    let index = group.x + group.y * ROW;
    if index >= params.clusters {
        return vec4<u32>(0u);
    }
    let c = clusters[index];
    return vec4<u32>(index, select(0u, 1u, k < (c.flags & CLUSTER_COUNT)), c.first + k, 0u);
}

@compute @workgroup_size(32)
fn farthest_point(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) k: u32) {
    let at = page_point(group, k);
    if at.y == 0u {
        return;
    }
    let d = decode_point(at.z, clusters[at.x]) - params.center;
    atomicMax(&output[0], bitcast<u32>(dot(d, d)));
}

@compute @workgroup_size(32)
fn decode_points(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) k: u32) {
    let at = page_point(group, k);
    if at.y == 0u {
        return;
    }
    let p = decode_point(at.z, clusters[at.x]);
    atomicStore(&output[4u * at.z], bitcast<u32>(p.x));
    atomicStore(&output[4u * at.z + 1u], bitcast<u32>(p.y));
    atomicStore(&output[4u * at.z + 2u], bitcast<u32>(p.z));
}

@compute @workgroup_size(64)
fn select_clusters(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = id.x + id.y * groups.x * 64u;
    if i >= params.clusters {
        return;
    }
    let flags = 8u * i + 5u;
    let out = (deselected[i / 32u] >> (i % 32u)) & 1u;
    let kept = atomicLoad(&output[flags]) & ~DESELECTED;
    atomicStore(&output[flags], kept | select(0u, DESELECTED, out != 0u));
}
