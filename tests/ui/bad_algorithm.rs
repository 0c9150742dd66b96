kanegen::dynamics!(Arm, "bad/negative_mass.toml", algorithm = "fastest");

fn main() {}
