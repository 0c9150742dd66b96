kanegen::dynamics!(Arm, "bad/negative_mass.toml", form = "rolled");

fn main() {}
