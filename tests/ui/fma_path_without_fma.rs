kanegen::dynamics!(Arm, "bad/negative_mass.toml", fma_path = f64::mul_add);

fn main() {}
