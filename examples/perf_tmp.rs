use mlt::*;
fn main() {
    let text = std::fs::read_to_string("tests/scenes/cornell-box.obj").unwrap();
    let mut pos = Vec::new();
    let mut idx = Vec::new();
    let mut mids = Vec::new();
    let names = ["white", "red", "green", "light"];
    let mut cur = 0u32;
    for line in text.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        if t.is_empty() {
            continue;
        }
        match t[0] {
            "v" => {
                for i in 1..4 {
                    pos.push(t[i].parse::<f32>().unwrap())
                }
            }
            "usemtl" => cur = names.iter().position(|n| *n == t[1]).unwrap() as u32,
            "f" => {
                for i in 1..4 {
                    idx.push(t[i].parse::<u32>().unwrap() - 1)
                }
                mids.push(cur)
            }
            _ => {}
        }
    }
    let mats = [
        Material::diffuse([0.725, 0.71, 0.68]),
        Material::diffuse([0.63, 0.065, 0.05]),
        Material::diffuse([0.14, 0.45, 0.091]),
        Material::diffuse([0.0; 3]).with_emission([17.0, 12.0, 4.0]),
    ];
    let scene = Scene::new(&SceneDesc {
        positions: &pos,
        indices: &idx,
        material_ids: &mids,
        materials: &mats,
        backend: Backend::Bvh,
    })
    .unwrap();
    let threads: u32 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1);
    let spp: u32 = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(64);
    let settings = RenderSettings {
        threads,
        samples_per_pixel: spp,
        ..Default::default()
    };
    let mut img = vec![0f32; 256 * 256 * 3];
    let st = render(&scene, &Camera::default(), &settings, &mut img, None).unwrap();
    let mean: Vec<f64> = (0..3)
        .map(|c| {
            img.iter()
                .skip(c)
                .step_by(3)
                .map(|&v| v as f64)
                .sum::<f64>()
                / 65536.0
        })
        .collect();
    println!(
        "{:?} samples/s {:.0} Mrays/s {:.2} rays/sample {:.2} mean {:?}",
        st.seconds,
        st.samples as f64 / st.seconds,
        st.rays as f64 / st.seconds / 1e6,
        st.rays as f64 / st.samples as f64,
        mean
    );
}
