kanegen::scene!(Bad, "bad/scene_unknown_key.toml");

fn main() {}
