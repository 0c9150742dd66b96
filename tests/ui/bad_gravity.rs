kanegen::dynamics!(Arm, "two_link.toml", gravity = [1e309, 0.0, 0.0]);

fn main() {}
