//! The text formats of the outside contract: OBJ meshes, point sets and segments. Text in,
//! typed data out: no file system here, so the page uses the same readers as the CLI.

mod obj;
mod point_set;

pub use obj::{ObjError, parse_obj, write_obj};
pub use point_set::{PointSetError, parse_points, parse_segments};
