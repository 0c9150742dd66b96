kanegen::dynamics!(Arm, "bad/negative_mass.toml", snap = 0.5);

fn main() {}
