kanegen::dynamics!(Arm, "bad/no_such_model.urdf");

fn main() {}
