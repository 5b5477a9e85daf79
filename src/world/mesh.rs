//! Triangle meshes from OBJ (via `tobj`) or STL (via `stl_io`) files.

use crate::math::Vec3;
use std::path::Path;

/// Vertices and triangles of a mesh file, with the reason when it cannot be used.
pub fn load(path: &Path) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), String> {
    if !path.exists() {
        return Err(format!("file '{}' not found", path.display()));
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    let (verts, tris) = match ext.as_str() {
        "obj" => load_obj(path)?,
        "stl" => load_stl(path)?,
        _ => {
            return Err(format!(
                "'{}': unknown mesh format (use .obj or .stl)",
                path.display()
            ))
        }
    };
    if tris.is_empty() {
        return Err(format!("'{}' holds no triangle", path.display()));
    }
    if let Some(v) = verts.iter().find(|v| !v.is_finite()) {
        return Err(format!(
            "'{}' has a non-finite vertex {v:?}",
            path.display()
        ));
    }
    let n = verts.len() as u32;
    if let Some(t) = tris.iter().find(|t| t.iter().any(|&i| i >= n)) {
        return Err(format!(
            "'{}': triangle {t:?} refers to a vertex beyond the {n} given",
            path.display()
        ));
    }
    let area: f64 = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| verts[i as usize]);
            (b - a).cross(c - a).length() / 2.0
        })
        .sum();
    if area.is_nan() || area <= 0.0 {
        return Err(format!(
            "'{}': every triangle is degenerate (zero area)",
            path.display()
        ));
    }
    Ok((verts, tris))
}

fn load_obj(path: &Path) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), String> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) =
        tobj::load_obj(path, &opts).map_err(|e| format!("'{}': {e}", path.display()))?;
    let mut verts = Vec::new();
    let mut tris = Vec::new();
    for m in models {
        let base = verts.len() as u32;
        let p = &m.mesh.positions;
        for v in p.chunks_exact(3) {
            verts.push(Vec3::new(v[0], v[1], v[2]));
        }
        for t in m.mesh.indices.chunks_exact(3) {
            tris.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    Ok((verts, tris))
}

fn load_stl(path: &Path) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), String> {
    let mut f = std::fs::File::open(path).map_err(|e| format!("'{}': {e}", path.display()))?;
    let mesh = stl_io::read_stl(&mut f).map_err(|e| format!("'{}': {e}", path.display()))?;
    let verts = mesh
        .vertices
        .iter()
        .map(|v| Vec3::new(v[0] as f64, v[1] as f64, v[2] as f64))
        .collect();
    let tris = mesh
        .faces
        .iter()
        .map(|f| f.vertices.map(|i| i as u32))
        .collect();
    Ok((verts, tris))
}
