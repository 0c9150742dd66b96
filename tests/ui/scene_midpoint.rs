kanegen::scene!(Bad, "bad/scene_midpoint.toml");

fn main() {}
