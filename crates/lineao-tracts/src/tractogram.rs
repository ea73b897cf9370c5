/// Streamlines as one flat array of points: streamline i is
/// `positions[offsets[i] as usize..offsets[i + 1] as usize]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tractogram {
    /// Points in RAS+ millimetres (or the scene's world units).
    pub positions: Vec<[f32; 3]>,
    /// N + 1 entries, first 0, last `positions.len()`.
    pub offsets: Vec<u64>,
}

impl Tractogram {
    pub fn new() -> Tractogram {
        Tractogram { positions: Vec::new(), offsets: vec![0] }
    }

    /// Appends one streamline.
    pub fn push(&mut self, points: impl IntoIterator<Item = [f32; 3]>) {
        if self.offsets.is_empty() {
            self.offsets.push(0);
        }
        self.positions.extend(points);
        self.offsets.push(self.positions.len() as u64);
    }

    pub fn streamlines(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    pub fn vertices(&self) -> usize {
        self.positions.len()
    }

    /// The points of streamline `i`.
    pub fn streamline(&self, i: usize) -> &[[f32; 3]] {
        &self.positions[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }
}
