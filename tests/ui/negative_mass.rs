kanegen::dynamics!(Arm, "bad/negative_mass.toml");

fn main() {}
