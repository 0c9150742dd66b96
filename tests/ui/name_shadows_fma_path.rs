// The type's name is the first segment of the fma path: one error at the name, not the
// compiler's errors over every fused call of the generated code.
kanegen::dynamics!(f64, "two_link.toml", fma = true, fma_path = f64::mul_add);

fn main() {}
