//! Context surfaces: triangle meshes from glTF (every triangle mode, node transforms) and OBJ
//! (polygons triangulated, normals from the file or the faces), gzip, and bad input.

use std::io::Write;
use std::path::{Path, PathBuf};

use glam::Vec3;
use lineao_tracts::{TriangleMesh, load_mesh};

fn shared(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data").join(path)
}

fn write(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn face_normal(mesh: &TriangleMesh, t: usize) -> Vec3 {
    let [a, b, c] = [0, 1, 2].map(|k| Vec3::from_array(mesh.positions[mesh.indices[3 * t + k] as usize]));
    (b - a).cross(c - a).normalize()
}

#[test]
fn the_gltf_sample_has_sixteen_triangles_in_three_modes() {
    // MeshPrimitiveModes: TRIANGLES (18 indices), TRIANGLE_STRIP (6), TRIANGLE_FAN (8) beside
    // point and line primitives, each mesh on its own node; everything lies in the plane z = 0.
    let mesh = load_mesh(shared("KhronosGroup+glTF-Sample-Models/2.0/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf"))
        .unwrap();
    assert_eq!(mesh.triangles(), 6 + 4 + 6);
    assert!(mesh.positions.iter().all(|p| p[2] == 0.0));
    // The triangle meshes sit on the nodes translated by y = −3 (x = −2, 0, 2).
    assert!(mesh.positions.iter().all(|p| p[1] <= -2.0), "{:?}", mesh.positions);
    // A strip's every other triangle is wound the other way: after the fix-up all face one side.
    for t in 0..mesh.triangles() {
        assert!(face_normal(&mesh, t).z > 0.99, "triangle {t}");
    }
    // No NORMAL attribute: face normals, here +z everywhere.
    assert!(mesh.normals.iter().all(|n| (Vec3::from_array(*n) - Vec3::Z).length() < 1e-6));
    assert_eq!(mesh.normals.len(), mesh.positions.len());
}

const CUBE: &str = "o cube
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1
vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0
f 1//1 4//1 3//1 2//1
f 5//2 6//2 7//2 8//2
f 1//3 2//3 6//3 5//3
f 4//4 8//4 7//4 3//4
f 1//5 5//5 8//5 4//5
f 2//6 3//6 7//6 6//6
";

#[test]
fn obj_quads_are_triangulated_with_the_file_normals() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = load_mesh(write(&dir, "cube.obj", CUBE.as_bytes())).unwrap();
    assert_eq!(mesh.triangles(), 12);
    // Each face's triangles face where its normal says (outward).
    for t in 0..12 {
        let n = Vec3::from_array(mesh.normals[mesh.indices[3 * t] as usize]);
        assert!(face_normal(&mesh, t).dot(n) > 0.99, "triangle {t}");
        let centre = [0, 1, 2].map(|k| Vec3::from_array(mesh.positions[mesh.indices[3 * t + k] as usize]));
        let centre = (centre[0] + centre[1] + centre[2]) / 3.0;
        assert!((centre - Vec3::splat(0.5)).dot(n) > 0.0, "triangle {t} normal points inward");
    }
    // gzip-wrapped, the same mesh.
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(CUBE.as_bytes()).unwrap();
    assert_eq!(load_mesh(write(&dir, "cube.obj.gz", &gz.finish().unwrap())).unwrap(), mesh);
}

#[test]
fn without_normals_they_come_from_the_faces() {
    // A pyramid over the unit square: the apex's normal is the area-weighted mean of its faces.
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nf 4 3 2 1\n";
    let dir = tempfile::tempdir().unwrap();
    let mesh = load_mesh(write(&dir, "pyramid.obj", obj.as_bytes())).unwrap();
    assert_eq!(mesh.triangles(), 6);
    let apex = mesh.positions.iter().position(|p| p[2] == 1.0).unwrap();
    assert!((Vec3::from_array(mesh.normals[apex]) - Vec3::Z).length() < 1e-6);
    for n in &mesh.normals {
        assert!((Vec3::from_array(*n).length() - 1.0).abs() < 1e-6);
    }
}

#[test]
fn files_without_triangles_and_broken_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    for (path, needle) in [
        (shared("Twinklebear+tobj/obj/lines.obj"), "faces"),
        (write(&dir, "empty.obj", b""), "faces"),
        (write(&dir, "bad-index.obj", b"v 0 0 0\nv 1 0 0\nf 1 2 9\n"), "obj"),
        (write(&dir, "binary.obj", &[0xff, 0xfe, 0x00, 0x41]), "UTF-8"),
        (write(&dir, "lines.gltf", br#"{"asset": {"version": "2.0"}, "meshes": []}"#), "triangles"),
        (dir.path().join("missing.obj"), "missing.obj"),
    ] {
        let error = load_mesh(&path).unwrap_err().to_string();
        assert!(error.contains(path.file_name().unwrap().to_str().unwrap()), "{error}");
        assert!(error.to_lowercase().contains(&needle.to_lowercase()), "{}: {error}", path.display());
    }
    // Every truncation and many byte mutations: an error or a mesh, never a panic (the glTF
    // with its external buffer beside it).
    std::fs::copy(
        shared("KhronosGroup+glTF-Sample-Models/2.0/MeshPrimitiveModes/glTF/buffer.bin"),
        dir.path().join("buffer.bin"),
    )
    .unwrap();
    let gltf =
        std::fs::read(shared("KhronosGroup+glTF-Sample-Models/2.0/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf"))
            .unwrap();
    for (name, bytes) in [("cube.obj", CUBE.as_bytes().to_vec()), ("modes.gltf", gltf)] {
        for cut in (0..bytes.len()).step_by(7) {
            let _ = load_mesh(write(&dir, name, &bytes[..cut]));
        }
        for k in 0..300u32 {
            let mut mutated = bytes.clone();
            let at = (k as usize * 7919) % mutated.len();
            mutated[at] = mutated[at].wrapping_add(1 + (k % 13) as u8);
            let _ = load_mesh(write(&dir, name, &mutated));
        }
    }
}
