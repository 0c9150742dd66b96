kanegen::scene!(Bad, "bad/scene_computed_torque_wrench.toml");

fn main() {}
