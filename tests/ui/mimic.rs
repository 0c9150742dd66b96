kanegen::dynamics!(Hand, "bad/mimic.urdf");

fn main() {}
