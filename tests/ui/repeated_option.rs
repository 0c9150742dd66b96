kanegen::dynamics!(Arm, "two_link.toml", fma = true, scalar = f32, fma = false);

fn main() {}
