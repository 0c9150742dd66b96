kanegen::dynamics!(Arm, "bad/unknown_key.toml");

fn main() {}
