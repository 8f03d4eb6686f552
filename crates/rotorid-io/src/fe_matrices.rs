//! The matrices file of a finite-element rotor (docs/formats.md): an NPZ archive,
//! as `numpy.savez` or `numpy.savez_compressed` writes it, of
//!
//! | member | dtype | shape | holds |
//! |---|---|---|---|
//! | `M` | float64 | n x n | mass (kg; kg m on displacement-rotation entries; kg m^2 on rotations) |
//! | `K` | float64 | n x n | stiffness of the shaft and disks, no bearings (N/m; N or N m/rad likewise) |
//! | `G` | float64 | n x n | gyroscopic matrix, multiplied by phi' (kg, kg m, kg m^2) |
//! | `C` (optional) | float64 | n x n | damping of the shaft, no bearings (N s/m, ...) |
//! | `Ka` (optional) | float64 | n x n | the matrix multiplied by phi'' (ROSS's `Ksdt`; kg, ...) |
//! | `dofs` | text | n | the degree of freedom of each row and column, `<node>.<dof>` |
//!
//! with dof one of `x`, `y`, `rx`, `ry` (checked by the rotor model, `rotorid::model::
//! finite_element::Dof`, not here). `dofs` may be a unicode array (`<U..`, what numpy
//! saves a list of `str` as: UTF-32, fixed width, NUL padded) or a bytes array (`|S..`,
//! UTF-8); trailing NULs are removed as numpy removes them. The matrices may be in C or
//! Fortran order, either byte order; they are returned row-major. Nothing else is checked
//! here (finiteness, symmetry and definiteness are the model's): values pass through as
//! stored.
//!
//! Refused, with an error ([`ReadError::Member`]) naming the file, the member, what it
//! holds and what is allowed: a missing `M`, `K`, `G` or `dofs`; a matrix that is not n x
//! n with n the number of `dofs`; a dtype other than float64 for a matrix or text for
//! `dofs`; and any other member (`Ksdt`, `c`, `arr_0`, ...): a member we
//! do not know would otherwise be dropped without a word, and a damping matrix saved as
//! `c` or a `Ksdt` not renamed `Ka` would silently change the rotor. Members not ending in
//! `.npy` (numpy never writes them) are skipped, as [`crate::npz`] skips them; of two
//! members of one name (which the zip format allows), the last is read, as numpy reads it. Every
//! lower-level fault (zip, NPY header, truncation) is [`crate::npz`]'s error, naming the
//! member as its channel.
//!
//! [`npz_bytes`] writes the same members back (stored, C order, `<f8` and `<U..`), read by
//! numpy as by [`read`].

use std::io::Write as _;
use std::path::Path;

use crate::cursor::Cursor;
use crate::error::ReadError;
use crate::npy::{self, Array};
use crate::write::WriteError;

/// The members of a matrices file, in the order [`npz_bytes`] writes them.
pub const MEMBERS: [&str; 6] = ["dofs", "M", "K", "G", "C", "Ka"];

/// What a matrices file holds: the degrees of freedom and the matrices, each n x n
/// row-major (entry (i, j) at `i * n + j`), in SI units (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct FeMatricesFile {
    /// The file, as named in messages.
    pub file: String,
    /// The name of each row and column, `<node>.<dof>` as stored.
    pub dofs: Vec<String>,
    /// Mass matrix M (kg, kg m, kg m^2).
    pub m: Vec<f64>,
    /// Stiffness matrix K of the shaft and disks (N/m, N, N m/rad).
    pub k: Vec<f64>,
    /// Gyroscopic matrix G, multiplied by phi' (kg, kg m, kg m^2).
    pub g: Vec<f64>,
    /// Damping matrix C of the shaft, if present (N s/m, ...).
    pub c: Option<Vec<f64>>,
    /// The matrix multiplied by phi'' (ROSS's Ksdt), if present (kg, ...).
    pub ka: Option<Vec<f64>>,
}

impl FeMatricesFile {
    /// The number of degrees of freedom n.
    pub fn n(&self) -> usize {
        self.dofs.len()
    }
}

/// Reads a matrices file's bytes; `file` names it in messages.
pub fn read(file: &str, bytes: &[u8]) -> Result<FeMatricesFile, ReadError> {
    let mut found = Found::default();
    crate::npz::members(
        file,
        std::io::Cursor::new(bytes),
        bytes.len() as u64,
        bytes,
        |name, c| found.member(file, name, c),
    )?;
    found.finish(file)
}

/// Reads the matrices file at `path`, member by member; `file` names it in messages.
pub fn read_file(file: &str, path: &Path) -> Result<FeMatricesFile, ReadError> {
    let disk = crate::source::DiskFile::open(file, path)?;
    let mut found = Found::default();
    crate::npz::members(
        file,
        std::io::BufReader::new(disk.handle()?),
        disk.size,
        &disk,
        |name, c| found.member(file, name, c),
    )?;
    found.finish(file)
}

/// The members read so far.
#[derive(Default)]
struct Found {
    /// `(member, array)` in the archive's order.
    arrays: Vec<(&'static str, Array)>,
}

fn member_error(file: &str, member: &str, found: String, allowed: String) -> ReadError {
    ReadError::Member {
        file: file.to_string(),
        member: member.to_string(),
        found,
        allowed,
    }
}

/// `38 x 40`, `(40,)`, `()` as the message shows a shape.
fn shape_text(shape: &[u64]) -> String {
    match shape {
        [r, c] => format!("{r} x {c}"),
        [n] => format!("of shape ({n},)"),
        _ => format!(
            "of shape ({})",
            shape
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

impl Found {
    fn member(&mut self, file: &str, name: &str, c: &mut Cursor) -> Result<(), ReadError> {
        let Some(&member) = MEMBERS.iter().find(|m| **m == name) else {
            let hint = match name.to_ascii_lowercase().as_str() {
                "ksdt" => " (ROSS's Ksdt is saved as Ka)".to_owned(),
                lower => MEMBERS
                    .iter()
                    .find(|m| m.to_ascii_lowercase() == lower)
                    .map_or(String::new(), |m| {
                        format!(" (names are case-sensitive: {m}?)")
                    }),
            };
            return Err(member_error(
                file,
                name,
                "is not a member of a matrices file".into(),
                format!(
                    "allowed members are M, K, G, dofs and optionally C, Ka{hint}; an unknown \
                     one is refused rather than ignored"
                ),
            ));
        };
        let array = npy::parse_array(c, member)?;
        self.arrays.push((member, array));
        Ok(())
    }

    fn take(&mut self, member: &str) -> Option<Array> {
        let i = self.arrays.iter().position(|(m, _)| *m == member)?;
        Some(self.arrays.remove(i).1)
    }

    fn finish(mut self, file: &str) -> Result<FeMatricesFile, ReadError> {
        let missing = |member: &str, what: &str| {
            member_error(
                file,
                member,
                "is missing".into(),
                format!("a matrices file must have M, K, G and dofs ({member}: {what})"),
            )
        };
        let dofs = match self.take("dofs") {
            None => return Err(missing("dofs", "n strings <node>.<dof>, e.g. 3.x")),
            Some(Array::Text { shape, data }) if shape.len() == 1 && !data.is_empty() => data,
            Some(Array::Text { shape, .. } | Array::F64 { shape, .. }) if shape.len() != 1 => {
                return Err(member_error(
                    file,
                    "dofs",
                    format!("is {}", shape_text(&shape)),
                    "must be one-dimensional: one string <node>.<dof> per row of the matrices"
                        .into(),
                ))
            }
            Some(Array::Text { .. }) => {
                return Err(member_error(
                    file,
                    "dofs",
                    "is empty".into(),
                    "must name at least one degree of freedom".into(),
                ))
            }
            Some(Array::F64 { .. }) => {
                return Err(member_error(
                    file,
                    "dofs",
                    "has dtype float64".into(),
                    "must be strings <node>.<dof> (a unicode array '<U..', what numpy saves a \
                     list of str as, or a bytes array '|S..')"
                        .into(),
                ))
            }
            Some(Array::Other { descr, .. }) => {
                return Err(member_error(
                    file,
                    "dofs",
                    format!("has dtype {descr:?}"),
                    "must be strings <node>.<dof>: a unicode array '<U..' (what numpy saves a \
                     list of str as) or a bytes array '|S..'; an object array needs pickle: \
                     save numpy.array(dofs, dtype=str)"
                        .into(),
                ))
            }
        };
        let n = dofs.len();
        let mut matrix = |member: &'static str,
                          what: &str,
                          required: bool|
         -> Result<Option<Vec<f64>>, ReadError> {
            match self.take(member) {
                None if required => Err(missing(member, what)),
                None => Ok(None),
                Some(Array::F64 { shape, data }) => {
                    if shape != [n as u64, n as u64] {
                        return Err(member_error(
                            file,
                            member,
                            format!("is {}", shape_text(&shape)),
                            format!(
                                "must be {n} x {n} (one row and column per entry of dofs, which \
                                 has {n})"
                            ),
                        ));
                    }
                    Ok(Some(data))
                }
                Some(Array::Text { .. }) => Err(member_error(
                    file,
                    member,
                    "holds strings".into(),
                    "must be float64 ('<f8' or '>f8')".into(),
                )),
                Some(Array::Other { descr, .. }) => Err(member_error(
                    file,
                    member,
                    format!("has dtype {descr:?}"),
                    "must be float64 ('<f8' or '>f8'): the matrices are taken as given, never \
                     converted"
                        .into(),
                )),
            }
        };
        let m = matrix("M", "the mass matrix", true)?.expect("required");
        let k = matrix("K", "the stiffness matrix, no bearings", true)?.expect("required");
        let g = matrix("G", "the gyroscopic matrix", true)?.expect("required");
        let c = matrix("C", "", false)?;
        let ka = matrix("Ka", "", false)?;
        Ok(FeMatricesFile {
            file: file.to_string(),
            dofs,
            m,
            k,
            g,
            c,
            ka,
        })
    }
}

/// The `.npy` bytes (version 1.0) of an array in C order with header `descr` and `shape`,
/// then `data`.
fn npy_bytes(descr: &str, shape: &str, data: &[u8]) -> Vec<u8> {
    npy_in_order(descr, false, shape, data)
}

/// [`npy_bytes`] in C or `fortran` order.
fn npy_in_order(descr: &str, fortran: bool, shape: &str, data: &[u8]) -> Vec<u8> {
    let order = if fortran { "True" } else { "False" };
    let mut header =
        format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {shape}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = Vec::with_capacity(12 + header.len() + data.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

/// `f` as an NPZ archive (stored members, as `numpy.savez`: `dofs` as `<U..`, the matrices
/// `<f8` in C order); `file` names it in errors. Refused: matrices that are not n x n,
/// no dofs.
pub fn npz_bytes(file: &str, f: &FeMatricesFile) -> Result<Vec<u8>, WriteError> {
    let n = f.n();
    let bad = |member: &str, why: String| WriteError::Unrepresentable {
        file: file.to_string(),
        channel: member.to_string(),
        why,
    };
    if n == 0 {
        return Err(bad("dofs", "no degree of freedom".into()));
    }
    let zerr = |e: &dyn std::fmt::Display| WriteError::Container {
        file: file.to_string(),
        container: "zip",
        message: e.to_string(),
    };
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Stored)
        .large_file(true);
    let width = f
        .dofs
        .iter()
        .map(|d| d.chars().count())
        .max()
        .unwrap_or(1)
        .max(1);
    let mut text = Vec::with_capacity(4 * width * n);
    for d in &f.dofs {
        let chars: Vec<char> = d.chars().collect();
        if chars.contains(&'\0') {
            return Err(bad(
                "dofs",
                format!("{d:?} holds a NUL, which numpy strips"),
            ));
        }
        for i in 0..width {
            let v = chars.get(i).map_or(0, |&ch| ch as u32);
            text.extend_from_slice(&v.to_le_bytes());
        }
    }
    let mut members: Vec<(&str, Vec<u8>)> = vec![(
        "dofs",
        npy_bytes(&format!("<U{width}"), &format!("({n},)"), &text),
    )];
    let matrices = [
        ("M", Some(&f.m)),
        ("K", Some(&f.k)),
        ("G", Some(&f.g)),
        ("C", f.c.as_ref()),
        ("Ka", f.ka.as_ref()),
    ];
    for (name, a) in matrices {
        let Some(a) = a else { continue };
        if a.len() != n * n {
            return Err(bad(
                name,
                format!("{} entries where n x n = {} (n = {n} dofs)", a.len(), n * n),
            ));
        }
        let data: Vec<u8> = a.iter().flat_map(|v| v.to_le_bytes()).collect();
        members.push((name, npy_bytes("<f8", &format!("({n}, {n})"), &data)));
    }
    for (name, bytes) in members {
        zip.start_file(format!("{name}.npy"), options)
            .map_err(|e| zerr(&e))?;
        zip.write_all(&bytes).map_err(|e| zerr(&e))?;
    }
    Ok(zip.finish().map_err(|e| zerr(&e))?.into_inner())
}

/// Writes `f` to `path` as [`npz_bytes`] makes it.
pub fn write(path: impl AsRef<Path>, f: &FeMatricesFile) -> Result<(), WriteError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let bytes = npz_bytes(&file, f)?;
    std::fs::write(path, bytes).map_err(|source| WriteError::Io { file, source })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(c: bool, ka: bool) -> FeMatricesFile {
        let n = 4;
        let mat = |s: f64| (0..n * n).map(|i| s * (i as f64 + 0.5)).collect::<Vec<_>>();
        FeMatricesFile {
            file: "rotor.npz".into(),
            dofs: ["0.x", "0.y", "0.rx", "12.ry"].map(String::from).to_vec(),
            m: mat(1.0),
            k: mat(1e6),
            g: mat(-0.25),
            c: c.then(|| mat(3.0)),
            ka: ka.then(|| mat(1e-3)),
        }
    }

    #[test]
    fn written_then_read_gives_the_same_file() {
        for (c, ka) in [(false, false), (true, false), (false, true), (true, true)] {
            let f = sample(c, ka);
            let bytes = npz_bytes("rotor.npz", &f).unwrap();
            assert_eq!(read("rotor.npz", &bytes).unwrap(), f);
        }
    }

    /// An archive's members: (name without `.npy`, bytes).
    type Members = Vec<(String, Vec<u8>)>;

    /// A member `name` of an archive, as `npy` bytes with a hand-written header.
    fn archive(members: &[(&str, Vec<u8>)]) -> Vec<u8> {
        let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let o = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        for (name, bytes) in members {
            zip.start_file(format!("{name}.npy"), o).unwrap();
            zip.write_all(bytes).unwrap();
        }
        zip.finish().unwrap().into_inner()
    }

    fn npy(descr: &str, fortran: bool, shape: &str, data: &[u8]) -> Vec<u8> {
        npy_in_order(descr, fortran, shape, data)
    }

    fn f8(v: &[f64], big: bool) -> Vec<u8> {
        v.iter()
            .flat_map(|x| {
                if big {
                    x.to_be_bytes()
                } else {
                    x.to_le_bytes()
                }
            })
            .collect()
    }

    #[test]
    fn fortran_order_big_endian_and_bytes_dofs_are_read() {
        // 2 x 2: M = [[1, 2], [3, 4]] stored column by column, big endian
        let m = [1.0, 3.0, 2.0, 4.0];
        let dofs = b"0.x\0\x000.y\0\0".to_vec();
        let bytes = archive(&[
            ("dofs", npy("|S5", false, "(2,)", &dofs)),
            ("M", npy(">f8", true, "(2, 2)", &f8(&m, true))),
            (
                "K",
                npy("<f8", false, "(2, 2)", &f8(&[1.0, 2.0, 3.0, 4.0], false)),
            ),
            ("G", npy("<f8", true, "(2, 2)", &f8(&m, false))),
        ]);
        let f = read("r.npz", &bytes).unwrap();
        assert_eq!(f.dofs, ["0.x", "0.y"]);
        assert_eq!(f.m, [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(f.k, [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(f.g, [1.0, 2.0, 3.0, 4.0]);
        assert_eq!((f.c, f.ka), (None, None));
    }

    #[test]
    fn faults_are_named_by_file_member_and_allowed() {
        let f = sample(false, false);
        let good = npz_bytes("rotor.npz", &f).unwrap();
        let zip = zip::ZipArchive::new(std::io::Cursor::new(good.clone())).unwrap();
        let mut members: Members = Vec::new();
        let mut z = zip;
        for i in 0..z.len() {
            let mut m = z.by_index(i).unwrap();
            let mut b = Vec::new();
            std::io::Read::read_to_end(&mut m, &mut b).unwrap();
            members.push((m.name().trim_end_matches(".npy").to_owned(), b));
        }
        let with = |edit: &dyn Fn(&mut Members)| {
            let mut m = members.clone();
            edit(&mut m);
            let refs: Vec<(&str, Vec<u8>)> =
                m.iter().map(|(n, b)| (n.as_str(), b.clone())).collect();
            read("rotor.npz", &archive(&refs)).unwrap_err().to_string()
        };
        // K 3 x 4 where dofs has 4
        let e = with(&|m| m[2].1 = npy("<f8", false, "(3, 4)", &f8(&[0.0; 12], false)));
        assert_eq!(
            e,
            "rotor.npz: member K is 3 x 4: must be 4 x 4 (one row and column per entry of dofs, which has 4)"
        );
        for (i, name) in [(0, "dofs"), (1, "M"), (2, "K"), (3, "G")] {
            let e = with(&|m| {
                m.remove(i);
            });
            assert!(
                e.starts_with(&format!("rotor.npz: member {name} is missing")),
                "{e}"
            );
        }
        let e = with(&|m| m[3].1 = npy("<f4", false, "(4, 4)", &[0u8; 64]));
        assert!(
            e.contains("member G has dtype \"<f4\"") && e.contains("float64"),
            "{e}"
        );
        let e = with(&|m| m.push(("Ksdt".into(), m[1].1.clone())));
        assert!(
            e.contains("member Ksdt is not a member") && e.contains("saved as Ka"),
            "{e}"
        );
        let e = with(&|m| m.push(("c".into(), m[1].1.clone())));
        assert!(e.contains("member c is not") && e.contains("C?"), "{e}");
        // a member twice (the zip writer refuses it: renamed in the bytes, same length) is
        // read as numpy reads it, the last one (the zip crate keeps the last of a name)
        let mut twice = members.clone();
        twice.push(("Q".into(), members[2].1.clone()));
        let refs: Vec<(&str, Vec<u8>)> =
            twice.iter().map(|(n, b)| (n.as_str(), b.clone())).collect();
        let mut bytes = archive(&refs);
        for k in 0..bytes.len() - 5 {
            if &bytes[k..k + 5] == b"Q.npy" {
                bytes[k] = b'M';
            }
        }
        assert_eq!(read("rotor.npz", &bytes).unwrap().m, f.k);
        let e = with(&|m| m[0].1 = npy("|O", false, "(4,)", &[0u8; 32]));
        assert!(
            e.contains("member dofs has dtype \"|O\"") && e.contains("dtype=str"),
            "{e}"
        );
        let e = with(&|m| m[0].1 = npy("<U3", false, "(2, 2)", &[0u8; 48]));
        assert!(
            e.contains("member dofs is 2 x 2: must be one-dimensional"),
            "{e}"
        );
        let e = with(&|m| m[0].1 = npy("<U3", false, "(0,)", &[]));
        assert!(e.contains("member dofs is empty"), "{e}");
        // a truncated member: the npz reader's error, naming the member
        let e = with(&|m| {
            let len = m[1].1.len();
            m[1].1.truncate(len - 8)
        });
        assert!(
            e.starts_with("rotor.npz, channel \"M\"") && e.contains("needs 128"),
            "{e}"
        );
        // a code point beyond Unicode
        let mut bad = vec![0u8; 48];
        bad[..4].copy_from_slice(&0x11_0000u32.to_le_bytes());
        let e = with(&|m| m[0].1 = npy("<U3", false, "(4,)", &bad));
        assert!(e.contains("0x110000") && e.contains("UTF-32"), "{e}");
    }
}
