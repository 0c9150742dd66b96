kanegen::scene!(Hand, "bad/scene_mimic_joint.toml");

fn main() {}
