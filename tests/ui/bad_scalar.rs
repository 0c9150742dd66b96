kanegen::dynamics!(Arm, "bad/negative_mass.toml", scalar = f16);

fn main() {}
