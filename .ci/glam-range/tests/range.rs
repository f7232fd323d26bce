#[test]
fn a_renderers_own_glam_goes_in_and_comes_out() {
    let (p, n) = octoray_glam_range::trace(0.25, 0.75).expect("a hit");
    assert!((p - glam::Vec3::new(0.25, 0.75, 0.0)).length() < 1e-6, "{p}");
    assert_eq!(n, glam::Vec3::Z);
    assert_eq!(octoray_glam_range::trace(1.5, 0.5), None);
}
