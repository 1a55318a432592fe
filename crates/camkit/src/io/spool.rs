//! Spools: what a filter makes in one stage and reads back in a later one, kept on disk (an
//! unnamed temporary file, removed when dropped) instead of in memory, so that a long program
//! costs disk, not memory.
//!
//! - [`Spool`]: bytes written once, then read back from the start as streams ([`Spooled`]), as
//!   often as needed and several at a time (each reader has its own position).
//! - [`RecordSpool`]: values of one fixed-size [`Record`] type appended, read and overwritten by
//!   index through a one-page cache; finished, [`Records`] hands out read-only [`View`]s, one per
//!   thread, each with its own two-page cache, so a search that stays near one place reads from
//!   memory and a full scan reads the file in order.
//! - [`Get`] (indexed reads) and [`Share`] (views for many threads) are what an algorithm takes so
//!   that it runs on slices in memory and on records on disk alike.
//!
//! Records cannot meet bad input, only a failing disk (a full one, or one gone): their reads and
//! writes unwind on an I/O error with a [`DiskFailure`], naming it, so that the geometry that
//! reads them stays free of error paths no input can reach; [`crate::cli::run`] turns it into a
//! runtime failure (one line, exit 1, the output not written). A [`Spool`] of bytes returns its
//! errors, as any writer.

use std::cell::RefCell;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::marker::PhantomData;
use std::os::unix::fs::FileExt;

/// Bytes per page of a record file: the unit it is read and written in.
const PAGE_BYTES: usize = 1 << 16;

/// Bytes written once into an unnamed temporary file, then read back: [`Spool::finish`].
#[derive(Debug)]
pub struct Spool {
    file: BufWriter<File>,
    len: u64,
}

impl Spool {
    /// An empty spool (its file is created now).
    pub fn new() -> std::io::Result<Spool> {
        Ok(Spool { file: BufWriter::with_capacity(PAGE_BYTES, tempfile::tempfile()?), len: 0 })
    }

    /// Bytes written so far.
    pub fn len(&self) -> u64 {
        self.len
    }

    /// True while nothing is written.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Ends writing: the spool to read back.
    pub fn finish(self) -> std::io::Result<Spooled> {
        let len = self.len;
        let file = self.file.into_inner().map_err(|e| e.into_error())?;
        Ok(Spooled { file, len })
    }
}

impl Write for Spool {
    fn write(&mut self, data: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(data)?;
        self.len += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

/// A spool written whole: read back from its start by any number of readers.
#[derive(Debug)]
pub struct Spooled {
    file: File,
    len: u64,
}

impl Spooled {
    /// Its length in bytes.
    pub fn len(&self) -> u64 {
        self.len
    }

    /// True if nothing was written.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// A buffered reader from the start, with its own position.
    pub fn reader(&self) -> BufReader<At<'_>> {
        BufReader::with_capacity(PAGE_BYTES, At { file: &self.file, pos: 0, end: self.len })
    }
}

/// A reader of a [`Spooled`] file at its own position.
#[derive(Debug)]
pub struct At<'a> {
    file: &'a File,
    pos: u64,
    end: u64,
}

impl Read for At<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = (self.end - self.pos).min(buf.len() as u64) as usize;
        if n == 0 {
            return Ok(0);
        }
        let got = self.file.read_at(&mut buf[..n], self.pos)?;
        self.pos += got as u64;
        Ok(got)
    }
}

/// A value kept in [`SIZE`](Record::SIZE) bytes, exactly (floating-point values bit for bit).
pub trait Record: Sized {
    /// Bytes a value takes.
    const SIZE: usize;
    /// Writes the value into `out` (`SIZE` bytes).
    fn put(&self, out: &mut Put);
    /// The value from `bytes` (`SIZE` bytes). All zeros must give a value (of any meaning).
    fn take(bytes: &mut Take) -> Self;
}

/// Writes the fields of a [`Record`] one after the other.
#[derive(Debug)]
pub struct Put<'a> {
    out: &'a mut [u8],
    at: usize,
}

impl Put<'_> {
    /// Next bytes.
    pub fn bytes(&mut self, b: &[u8]) -> &mut Self {
        self.out[self.at..self.at + b.len()].copy_from_slice(b);
        self.at += b.len();
        self
    }

    /// An `f64`, bit for bit.
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.bytes(&v.to_bits().to_le_bytes())
    }

    /// A `u64`.
    pub fn u64(&mut self, v: u64) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }

    /// A byte.
    pub fn u8(&mut self, v: u8) -> &mut Self {
        self.bytes(&[v])
    }

    /// An optional `f64`: a flag byte and the value (0 if none).
    pub fn opt_f64(&mut self, v: Option<f64>) -> &mut Self {
        self.u8(u8::from(v.is_some())).f64(v.unwrap_or(0.0))
    }
}

/// Reads the fields of a [`Record`] in the order [`Put`] wrote them.
#[derive(Debug)]
pub struct Take<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Take<'_> {
    /// The next `N` bytes.
    pub fn bytes<const N: usize>(&mut self) -> [u8; N] {
        let mut b = [0u8; N];
        b.copy_from_slice(&self.bytes[self.at..self.at + N]);
        self.at += N;
        b
    }

    /// An `f64`.
    pub fn f64(&mut self) -> f64 {
        f64::from_bits(u64::from_le_bytes(self.bytes()))
    }

    /// A `u64`.
    pub fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.bytes())
    }

    /// A byte.
    pub fn u8(&mut self) -> u8 {
        self.bytes::<1>()[0]
    }

    /// An optional `f64`.
    pub fn opt_f64(&mut self) -> Option<f64> {
        let some = self.u8() != 0;
        let v = self.f64();
        some.then_some(v)
    }
}

impl Record for u64 {
    const SIZE: usize = 8;
    fn put(&self, out: &mut Put) {
        out.u64(*self);
    }
    fn take(bytes: &mut Take) -> Self {
        bytes.u64()
    }
}

impl Record for crate::geom::P3 {
    const SIZE: usize = 24;
    fn put(&self, out: &mut Put) {
        out.f64(self.x).f64(self.y).f64(self.z);
    }
    fn take(bytes: &mut Take) -> Self {
        crate::geom::P3::new(bytes.f64(), bytes.f64(), bytes.f64())
    }
}

fn per_page<T: Record>() -> usize {
    (PAGE_BYTES / T::SIZE).max(1)
}

fn encode<T: Record>(v: &T, page: &mut [u8], slot: usize) {
    let at = slot * T::SIZE;
    v.put(&mut Put { out: &mut page[at..at + T::SIZE], at: 0 });
}

fn decode<T: Record>(page: &[u8], slot: usize) -> T {
    let at = slot * T::SIZE;
    T::take(&mut Take { bytes: &page[at..at + T::SIZE], at: 0 })
}

/// Reads page `p` of `count` records of `T` from `file` into `buf` (the part past the last
/// record zeroed).
fn read_page<T: Record>(file: &File, count: usize, p: usize, buf: &mut [u8]) -> std::io::Result<()> {
    let n = per_page::<T>();
    let records = count.saturating_sub(p * n).min(n);
    let want = records * T::SIZE;
    file.read_exact_at(&mut buf[..want], (p * n * T::SIZE) as u64)?;
    buf[want..].fill(0);
    Ok(())
}

/// A page of records held in memory.
#[derive(Debug)]
struct Page {
    index: usize,
    bytes: Vec<u8>,
    dirty: bool,
}

/// What a records' temporary file failing unwinds with (see the module's documentation).
#[derive(Debug)]
pub struct DiskFailure(pub String);

/// Unwinds for an I/O error of a temporary file (see the module's documentation).
fn failed(e: std::io::Error) -> ! {
    std::panic::panic_any(DiskFailure(format!("a temporary file cannot be written or read back: {e}")))
}

/// Records of one type by index: appended, read and overwritten through a one-page cache
/// (sequential work in either direction touches the disk once a page). The temporary file is
/// made when the first page is full: records that fit one page stay in memory.
#[derive(Debug)]
pub struct RecordSpool<T> {
    file: Option<File>,
    len: usize,
    page: Page,
    _t: PhantomData<fn() -> T>,
}

impl<T: Record> Default for RecordSpool<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Record> RecordSpool<T> {
    /// An empty spool.
    pub fn new() -> RecordSpool<T> {
        let bytes = vec![0u8; per_page::<T>() * T::SIZE];
        RecordSpool { file: None, len: 0, page: Page { index: 0, bytes, dirty: false }, _t: PhantomData }
    }

    /// Records held.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True if none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    fn file(&mut self) -> &File {
        if self.file.is_none() {
            self.file = Some(tempfile::tempfile().unwrap_or_else(|e| failed(e)));
        }
        self.file.as_ref().expect("made above")
    }

    /// Writes the cached page back if it was changed.
    fn write_back(&mut self) {
        if self.page.dirty {
            let n = per_page::<T>();
            let records = self.len.saturating_sub(self.page.index * n).min(n);
            let at = (self.page.index * n * T::SIZE) as u64;
            let bytes = std::mem::take(&mut self.page.bytes);
            self.file().write_all_at(&bytes[..records * T::SIZE], at).unwrap_or_else(|e| failed(e));
            self.page.bytes = bytes;
            self.page.dirty = false;
        }
    }

    /// The cache on the page of record `i`; `i`'s slot in it.
    fn load(&mut self, i: usize) -> usize {
        let n = per_page::<T>();
        let p = i / n;
        if self.page.index != p {
            self.write_back();
            let len = self.len;
            let mut bytes = std::mem::take(&mut self.page.bytes);
            if len > p * n {
                read_page::<T>(self.file(), len, p, &mut bytes).unwrap_or_else(|e| failed(e));
            } else {
                bytes.fill(0);
            }
            self.page = Page { index: p, bytes, dirty: false };
        }
        i - p * n
    }

    /// Appends a record.
    pub fn push(&mut self, v: &T) {
        let slot = self.load(self.len);
        encode(v, &mut self.page.bytes, slot);
        self.page.dirty = true;
        self.len += 1;
    }

    /// Replaces record `i` (< [`RecordSpool::len`]).
    pub fn set(&mut self, i: usize, v: &T) {
        assert!(i < self.len, "record {i} of {}", self.len);
        let slot = self.load(i);
        encode(v, &mut self.page.bytes, slot);
        self.page.dirty = true;
    }

    /// Record `i` (< [`RecordSpool::len`]).
    pub fn get(&mut self, i: usize) -> T {
        assert!(i < self.len, "record {i} of {}", self.len);
        let slot = self.load(i);
        decode(&self.page.bytes, slot)
    }

    /// Ends writing: the records to read.
    pub fn finish(mut self) -> Records<T> {
        self.page.dirty |= self.file.is_none();
        self.write_back();
        let file = self.file.take().expect("written back");
        Records { file, len: self.len, _t: PhantomData }
    }
}

/// Records written whole, read through [`View`]s (any number, on any threads).
#[derive(Debug)]
pub struct Records<T> {
    file: File,
    len: usize,
    _t: PhantomData<fn() -> T>,
}

impl<T: Record> Records<T> {
    /// Records held.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True if none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// A reader with its own cache of two pages.
    pub fn view(&self) -> View<'_, T> {
        let page = || (usize::MAX, vec![0u8; per_page::<T>() * T::SIZE]);
        View { file: &self.file, len: self.len, pages: RefCell::new([page(), page()]), _t: PhantomData }
    }

    /// Every record in order.
    pub fn iter(&self) -> impl Iterator<Item = T> + '_ {
        let view = self.view();
        (0..self.len).map(move |i| view.get(i))
    }
}

/// A reader of [`Records`] with a cache of two pages (the one read last first): a search moving
/// to and fro across a page boundary reads each page once.
#[derive(Debug)]
pub struct View<'a, T> {
    file: &'a File,
    len: usize,
    pages: RefCell<[(usize, Vec<u8>); 2]>,
    _t: PhantomData<fn() -> T>,
}

/// Indexed reads of values: a slice in memory, or records on disk through a [`View`].
pub trait Get<T> {
    /// Values held.
    fn len(&self) -> usize;
    /// Value `i` (< `len`).
    fn get(&self, i: usize) -> T;
    /// True if none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl<T: Record> Get<T> for View<'_, T> {
    fn len(&self) -> usize {
        self.len
    }

    fn get(&self, i: usize) -> T {
        assert!(i < self.len, "record {i} of {}", self.len);
        let n = per_page::<T>();
        let p = i / n;
        let mut pages = self.pages.borrow_mut();
        if pages[0].0 != p {
            pages.swap(0, 1);
            if pages[0].0 != p {
                read_page::<T>(self.file, self.len, p, &mut pages[0].1).unwrap_or_else(|e| failed(e));
                pages[0].0 = p;
            }
        }
        decode(&pages[0].1, i - p * n)
    }
}

impl<T: Copy> Get<T> for [T] {
    fn len(&self) -> usize {
        <[T]>::len(self)
    }

    fn get(&self, i: usize) -> T {
        self[i]
    }
}

impl<T: Copy> Get<T> for Vec<T> {
    fn len(&self) -> usize {
        self.as_slice().len()
    }

    fn get(&self, i: usize) -> T {
        self[i]
    }
}

impl<T: Copy, const N: usize> Get<T> for [T; N] {
    fn len(&self) -> usize {
        N
    }

    fn get(&self, i: usize) -> T {
        self[i]
    }
}

impl<T, G: Get<T> + ?Sized> Get<T> for &G {
    fn len(&self) -> usize {
        (**self).len()
    }

    fn get(&self, i: usize) -> T {
        (**self).get(i)
    }
}

/// Values that many threads read at once, each through its own [`Share::View`].
pub trait Share<T>: Sync {
    /// A reader for one thread.
    type View<'a>: Get<T>
    where
        Self: 'a;
    /// A new reader.
    fn view(&self) -> Self::View<'_>;
}

impl<T: Copy + Sync> Share<T> for [T] {
    type View<'a>
        = &'a [T]
    where
        Self: 'a;
    fn view(&self) -> &[T] {
        self
    }
}

impl<T: Copy + Sync> Share<T> for Vec<T> {
    type View<'a>
        = &'a [T]
    where
        Self: 'a;
    fn view(&self) -> &[T] {
        self
    }
}

impl<T: Copy + Sync, const N: usize> Share<T> for [T; N] {
    type View<'a>
        = &'a [T]
    where
        Self: 'a;
    fn view(&self) -> &[T] {
        self
    }
}

impl<T: Record> Share<T> for Records<T> {
    type View<'a>
        = View<'a, T>
    where
        Self: 'a;
    fn view(&self) -> View<'_, T> {
        Records::view(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::P3;
    use std::io::BufRead;

    /// A spool reads back what was written, from the start each time, two readers at once.
    #[test]
    fn a_spool_reads_back_from_its_start_as_often_as_asked() {
        let mut s = Spool::new().unwrap();
        for k in 0..20_000 {
            writeln!(s, "G1 X{k}").unwrap();
        }
        let len = s.len();
        let s = s.finish().unwrap();
        assert_eq!(s.len(), len);
        let (mut a, mut b) = (s.reader().lines(), s.reader().lines());
        for k in 0..20_000 {
            assert_eq!(a.next().unwrap().unwrap(), format!("G1 X{k}"));
            if k % 3 == 0 {
                assert_eq!(b.next().unwrap().unwrap(), format!("G1 X{}", k / 3));
            }
        }
        assert!(a.next().is_none());
        let mut all = String::new();
        s.reader().read_to_string(&mut all).unwrap();
        assert_eq!(all.len() as u64, len);
    }

    /// Records pushed over many pages, some overwritten, read back by index in any order (views
    /// and the spool itself), bit for bit.
    #[test]
    fn records_read_back_by_index_bit_for_bit() {
        let n = 3 * per_page::<P3>() + 17;
        let p = |k: usize| P3::new(k as f64 * 0.1, -(k as f64) / 3.0, f64::from_bits(k as u64 + 1));
        let mut s = RecordSpool::<P3>::new();
        for k in 0..n {
            s.push(&p(k));
        }
        // Backwards over every page, overwriting every seventh record.
        for k in (0..n).rev() {
            assert_eq!(s.get(k), p(k));
            if k % 7 == 0 {
                s.set(k, &p(k + n));
            }
        }
        let want = |k: usize| if k % 7 == 0 { p(k + n) } else { p(k) };
        assert_eq!(s.get(0), want(0));
        let r = s.finish();
        assert_eq!(r.len(), n);
        assert!(r.iter().enumerate().all(|(k, v)| v == want(k)));
        let (v, w) = (r.view(), r.view());
        let mut k = 1usize;
        for _ in 0..2000 {
            k = (k * 7919 + 13) % n;
            assert_eq!(v.get(k), want(k));
            assert_eq!(w.get(n - 1 - k), want(n - 1 - k));
        }
        // Slices answer the same way.
        let mem: Vec<P3> = (0..n).map(want).collect();
        assert_eq!(Get::len(&mem), n);
        assert_eq!(Get::get(&Share::view(&mem), 5), Get::get(&Share::view(&r), 5));
    }
}
