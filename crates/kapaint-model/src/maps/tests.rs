//! The maps' sizes, versions, copy-on-write and `k_a` derive.

use super::*;

#[test]
fn sizes_are_validated() {
    let base = MaterialValue::default();
    assert!(MaterialMaps::new(0, 10, base).is_err());
    assert!(MaterialMaps::new(8193, 10, base).is_err());
    let maps = MaterialMaps::new(100, 70, base).unwrap();
    assert_eq!((maps.tiles_x(), maps.tiles_y()), (2, 2));
    assert_eq!(
        maps.tile_rect(3),
        TexelRect {
            x0: 64,
            y0: 64,
            x1: 100,
            y1: 70
        }
    );
    assert_eq!(maps.heap_bytes(), 0);
    assert_eq!(maps.value(99, 69), base.quantized());
}

#[test]
fn writes_bump_versions_and_copy_on_write() {
    let mut maps = MaterialMaps::new(128, 128, MaterialValue::default()).unwrap();
    let v0 = maps.version();
    let held = Arc::clone(maps.tile(1));
    maps.tile_mut(1).n.data_mut()[0] = 7;
    assert_eq!(maps.tiles_changed_since(v0), vec![1]);
    assert_eq!(
        held.n.uniform(),
        Some(Texel::encode(MaterialValue::default()).n)
    );
    assert_eq!(maps.tile(1).n.get(0), 7);
    assert_eq!(maps.channels_changed_since(1, v0), Channels::ALL);
}

#[test]
fn versions_follow_the_channels_written() {
    let mut maps = MaterialMaps::new(128, 128, MaterialValue::default()).unwrap();
    let v0 = maps.version();
    let only_n = Channels {
        kd: false,
        ks: false,
        n: true,
    };
    maps.tiles_mut_many_in(&[0, 3], only_n)[1].n.data_mut()[5] = 9;
    assert_eq!(maps.tiles_changed_since(v0), vec![0, 3]);
    assert_eq!(maps.channels_changed_since(3, v0), only_n);
    assert!(maps.tile_version(3) > v0);
    let v1 = maps.version();
    assert!(maps.tiles_changed_since(v1).is_empty());
    maps.tile_mut(2);
    assert_eq!(maps.channels_changed_since(2, v1), Channels::ALL);
    assert_eq!(maps.channels_changed_since(3, v1), Channels::NONE);
}

#[test]
fn derive_matches_the_reflectance_core() {
    let mut maps = MaterialMaps::new(70, 65, MaterialValue::default()).unwrap();
    for (i, (x, y)) in [(0, 0), (69, 64), (10, 3)].into_iter().enumerate() {
        let v = MaterialValue::new(
            Vec3::new(0.1 * i as f32, 0.5, 0.9),
            Vec3::new(0.3, 0.2 * i as f32, 0.7),
            [0.0, 37.5, 9000.0][i],
        );
        let (id, j) = maps.locate(x, y);
        maps.tile_mut(id).set_texel(j, Texel::encode(v));
    }
    let mut out = vec![Vec3::ZERO; maps.texel_count()];
    for model in ShadingModel::ALL {
        for approx in AmbientApprox::ALL {
            maps.derive_ka_into(model, approx, &mut out);
            for (x, y) in [(0, 0), (69, 64), (10, 3), (5, 5)] {
                let v = maps.value(x, y);
                let want = reflectance::ka(model, approx, v.kd, v.ks, v.n);
                let got = out[(y * 70 + x) as usize];
                assert!((got - want).abs().max_element() < 1e-6, "{got} vs {want}");
            }
        }
    }
}
