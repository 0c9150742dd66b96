kanegen::dynamics!(Arm, "bad/triangle.toml");

fn main() {}
