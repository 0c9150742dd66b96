kanegen::dynamics!(Hand, "bad/mimic.urdf", form = "compact");

fn main() {}
