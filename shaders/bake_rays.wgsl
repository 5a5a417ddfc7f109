// AO and thickness rays of a bake from a high mesh, cast through the high mesh's compressed
// wide BVH as `kapaint_mesh::bakes::RayMesh::gpu_layout` lays it out: one invocation a query
// (a sample of a texel), its rays one after the other. The CPU's `CpuCaster` is the
// reference; this measures the same thing with the same directions.
//
// A node is 20 words: its origin (3 floats), the exponents and the internal-child mask (a
// byte each), the first child node, the first triangle, then 8 bytes each of the children's
// meta bytes, min x, max x, min y, max y, min z and max z. A child's box is `origin + 2^e * q` per
// axis. A child's meta byte is 0 where the slot is empty; an internal child's low 5 bits are 24
// plus its slot, its node the first child plus the internal children in earlier slots; a
// leaf's low 5 bits are its first triangle after the node's, its high 3 bits its triangles
// in unary.

struct Params {
    // Queries in this dispatch.
    count: u32,
    // Rays a query.
    directions: u32,
    // 0: the fraction open (AO); 1: the mean of min(distance, far) / far (thickness).
    kind: u32,
    // How far a ray looks (local units).
    far: f32,
    // Queries a row of the dispatch holds (its x workgroups times 64).
    row: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> nodes: array<u32>;
@group(0) @binding(2) var<storage, read> triangles: array<f32>;
@group(0) @binding(3) var<storage, read> directions: array<vec4<f32>>;
// Per query: origin and group (bits), t, b, n.
@group(0) @binding(4) var<storage, read> queries: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> results: array<f32>;

const NODE_WORDS: u32 = 20u;
const STACK: u32 = 128u;
const NO_GROUP: u32 = 0xffffffffu;

fn byte_of(word: u32, k: u32) -> u32 {
    return (word >> (8u * k)) & 0xffu;
}

// Byte `k` (0 to 7) of the 8-byte field starting at word `first` of node `node`.
fn node_byte(node: u32, first: u32, k: u32) -> u32 {
    return byte_of(nodes[node * NODE_WORDS + first + k / 4u], k % 4u);
}

fn corner(k: u32) -> vec3<f32> {
    return vec3<f32>(triangles[k], triangles[k + 1u], triangles[k + 2u]);
}

// The distance along the ray to triangle `k`, or -1 where it is missed or beyond `far`.
fn hit_triangle(origin: vec3<f32>, dir: vec3<f32>, k: u32, far: f32) -> f32 {
    let v0 = corner(k * 9u);
    let e1 = corner(k * 9u + 3u) - v0;
    let e2 = corner(k * 9u + 6u) - v0;
    let p = cross(dir, e2);
    let det = dot(e1, p);
    if det == 0.0 {
        return -1.0;
    }
    let inv = 1.0 / det;
    let s = origin - v0;
    let u = dot(s, p) * inv;
    let q = cross(s, e1);
    let v = dot(dir, q) * inv;
    if u < 0.0 || v < 0.0 || u + v > 1.0 {
        return -1.0;
    }
    let t = dot(e2, q) * inv;
    if t < 0.0 || t > far {
        return -1.0;
    }
    return t;
}

// The nearest triangle the ray meets within `far` (the first found where `any`): its
// distance, or -1.
fn trace(origin: vec3<f32>, dir: vec3<f32>, far_in: f32, first_hit: bool) -> f32 {
    var far = far_in;
    var best = -1.0;
    // A component of zero as the least normal value of its sign: the slabs stay ordered.
    let tiny = vec3<f32>(1e-30);
    let safe = select(dir, select(-tiny, tiny, dir >= vec3<f32>(0.0)), abs(dir) < tiny);
    let inv = 1.0 / safe;
    var stack: array<u32, STACK>;
    stack[0] = 0u;
    var top = 1u;
    while top > 0u {
        top -= 1u;
        let node = stack[top];
        let base = node * NODE_WORDS;
        let p = vec3<f32>(
            bitcast<f32>(nodes[base]),
            bitcast<f32>(nodes[base + 1u]),
            bitcast<f32>(nodes[base + 2u]),
        );
        let ew = nodes[base + 3u];
        let e = vec3<f32>(
            bitcast<f32>(byte_of(ew, 0u) << 23u),
            bitcast<f32>(byte_of(ew, 1u) << 23u),
            bitcast<f32>(byte_of(ew, 2u) << 23u),
        );
        let imask = byte_of(ew, 3u);
        let child_base = nodes[base + 4u];
        let triangle_base = nodes[base + 5u];
        for (var c = 0u; c < 8u; c += 1u) {
            let info = node_byte(node, 6u, c);
            if info == 0u {
                continue;
            }
            let lo = p + e * vec3<f32>(
                f32(node_byte(node, 8u, c)),
                f32(node_byte(node, 12u, c)),
                f32(node_byte(node, 16u, c)),
            );
            let hi = p + e * vec3<f32>(
                f32(node_byte(node, 10u, c)),
                f32(node_byte(node, 14u, c)),
                f32(node_byte(node, 18u, c)),
            );
            let t0 = (lo - origin) * inv;
            let t1 = (hi - origin) * inv;
            let near = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
            let leave = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), min(max(t0.z, t1.z), far));
            if near > leave {
                continue;
            }
            let low = info & 31u;
            if low >= 24u {
                let slot = low - 24u;
                let child = child_base + countOneBits(imask & ((1u << slot) - 1u));
                if top < STACK {
                    stack[top] = child;
                    top += 1u;
                }
                continue;
            }
            let first = triangle_base + low;
            let count = countOneBits(info & 0xe0u);
            for (var k = 0u; k < count; k += 1u) {
                let t = hit_triangle(origin, dir, first + k, far);
                if t >= 0.0 {
                    if first_hit {
                        return t;
                    }
                    far = t;
                    best = t;
                }
            }
        }
    }
    return best;
}

@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x + id.y * params.row;
    if i >= params.count {
        return;
    }
    let head = queries[i * 4u];
    if bitcast<u32>(head.w) == NO_GROUP {
        results[i] = 1.0;
        return;
    }
    let origin = head.xyz;
    let t = queries[i * 4u + 1u].xyz;
    let b = queries[i * 4u + 2u].xyz;
    let n = queries[i * 4u + 3u].xyz;
    var sum = 0.0;
    for (var k = 0u; k < params.directions; k += 1u) {
        let d = directions[k].xyz;
        let dir = t * d.x + b * d.y + n * d.z;
        if params.kind == 0u {
            if trace(origin, dir, params.far, true) < 0.0 {
                sum += 1.0;
            }
        } else {
            let h = trace(origin, dir, params.far, false);
            sum += select(1.0, h / params.far, h >= 0.0);
        }
    }
    results[i] = sum / f32(max(params.directions, 1u));
}
