//! The CPU's images: row-major, one value per pixel — what the reference computes on, `verify`
//! compares, the truth traces into. Its own module, below the reference and the methods that
//! re-export theirs through it ([`crate::reference`] names it for tools).

/// A row-major image, `data[y * width + x]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Image<T> {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The pixels, row-major, top row first.
    pub data: Vec<T>,
}

/// An ND map level: normal xyz, normalized depth w.
pub type NdImage = Image<[f32; 4]>;

impl<T: Copy> Image<T> {
    /// An image of `value` everywhere.
    pub fn filled(width: usize, height: usize, value: T) -> Image<T> {
        Image { width, height, data: vec![value; width * height] }
    }

    /// An image of `f(x, y)` at every pixel.
    pub fn from_fn(width: usize, height: usize, mut f: impl FnMut(usize, usize) -> T) -> Image<T> {
        let mut data = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                data.push(f(x, y));
            }
        }
        Image { width, height, data }
    }

    /// The pixel at (x, y).
    pub fn get(&self, x: usize, y: usize) -> T {
        self.data[y * self.width + x]
    }

    /// The texel at (x, y) clamped to the image.
    pub fn clamped(&self, x: i64, y: i64) -> T {
        let x = x.clamp(0, self.width as i64 - 1) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        self.get(x, y)
    }
}
