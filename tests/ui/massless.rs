kanegen::dynamics!(Hand, "bad/massless.urdf");

fn main() {}
