//! The real meshes load with the vertex and triangle counts their sources state.

use pt_scene::assets::find_asset_or_skip;
use pt_scene::load_mesh;

fn check(name: &str, vertices: usize, triangles: usize) {
    let Some(path) = find_asset_or_skip(name).unwrap() else {
        return;
    };
    let mesh = load_mesh(&path).unwrap();
    assert_eq!(mesh.geometry().positions().len(), vertices, "{name}");
    assert_eq!(mesh.geometry().triangle_count(), triangles, "{name}");
}

// OBJ files are read with one index per vertex, which keeps only the vertices faces use: the
// bunny has 1,113 unreferenced vertices and the res3 dragon 16 (counted in SOURCES.md).
#[test]
fn stanford_bunny_obj() {
    check("meshes/stanford-bunny.obj", 35_947 - 1_113, 69_451);
}

#[test]
fn low_resolution_bunny_obj() {
    check("meshes/bunny-lowres-npm.obj", 1_839, 3_674);
}

#[test]
fn dragon_res3_ascii_ply_and_obj_agree() {
    check("meshes/dragon_vrip_res3.ply", 22_998, 47_794);
    check("meshes/dragon_vrip_res3.obj", 22_998 - 16, 47_794);
    let (Some(a), Some(b)) = (
        find_asset_or_skip("meshes/dragon_vrip_res3.ply").unwrap(),
        find_asset_or_skip("meshes/dragon_vrip_res3.obj").unwrap(),
    ) else {
        return;
    };
    // Same triangles, corner for corner, in the same order.
    let (a, b) = (load_mesh(a).unwrap(), load_mesh(b).unwrap());
    for i in 0..a.geometry().triangle_count() {
        assert_eq!(
            a.geometry().triangle(i),
            b.geometry().triangle(i),
            "triangle {i}"
        );
    }
}

#[test]
fn dragon_res2_binary_ply() {
    check("meshes/dragon_vrip_res2.binary.ply", 100_250, 202_520);
}
