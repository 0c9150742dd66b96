kanegen::dynamics!(Arm, "bad/negative_mass.toml", color = 1);

fn main() {}
