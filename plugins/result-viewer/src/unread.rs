//! How much of an event stream the page has not read yet, from the socket.
//!
//! What: [`Unread`] watches the peer's advertised TCP receive window
//! (`tcpi_snd_wnd` of Linux's `TCP_INFO`, on kernels that report it) and tells when more
//! than the last write has sat unread in the page's receive buffer, and for
//! how long (the web server cuts the stream at 5 s); [`set_send_buffer`]
//! shrinks the server's own send buffer.
//!
//! Why: a write returns as soon as the kernel has the bytes, and the page's
//! receive buffer alone takes a few hundred KiB, so a page that never reads
//! used to hold its place until both buffers were full plus the write deadline
//! (13 s at ten 2 KB changes a second, minutes when the state changes
//! rarely). The peer's window shrinks by every byte it holds unread: that is
//! the only sign TCP gives of a page that stopped reading.
//!
//! How: the largest window seen is the page's empty buffer; that minus the
//! window now is what it holds unread. A page that reads shows at most its
//! last write unread (Linux sends no window update for a small read), so the
//! stream counts as stalled while more than the last write plus [`SLACK`] is
//! unread, since the write before the last (which the page has not taken
//! since), and is cut once stalled for the deadline. The page's
//! buffer still grows as data comes (the window's largest value rises a few
//! KiB after the first events), which only delays the cut by those bytes.
//! Elsewhere than Linux, or on an older kernel, nothing is measured and only
//! the write deadline holds.

use std::net::TcpStream;
use std::time::{Duration, Instant};

/// Unread bytes beyond the last write a reading page may still show (window
/// rounding, a window update not sent yet).
pub const SLACK: u32 = 1024;

/// What was written and what the peer's window told so far.
#[derive(Debug, Default)]
pub struct Unread {
    /// The largest window seen: the page's buffer with nothing unread.
    widest: u32,
    /// The length of the last write.
    last_len: usize,
    /// When the last and the one before were written.
    last_at: Option<Instant>,
    before_at: Option<Instant>,
    /// Since when more than the last write has been unread: the time of the
    /// write before it, which the page has not taken since.
    stalled_since: Option<Instant>,
}

impl Unread {
    /// Notes a write of `len` bytes, just done.
    pub fn wrote(&mut self, len: usize) {
        self.before_at = self.last_at.replace(Instant::now());
        self.last_len = len;
    }

    /// Looks at the window now: how long more than the last write has been
    /// unread (zero when it is not), or `None` when the window cannot be read.
    pub fn check(&mut self, stream: &TcpStream) -> Option<Duration> {
        let window = peer_window(stream)?;
        self.widest = self.widest.max(window);
        let unread = self.widest - window;
        let allowed = u32::try_from(self.last_len)
            .unwrap_or(u32::MAX)
            .saturating_add(SLACK);
        if unread <= allowed {
            self.stalled_since = None;
            return Some(Duration::ZERO);
        }
        let since = self.before_at.or(self.last_at).unwrap_or_else(Instant::now);
        Some(self.stalled_since.get_or_insert(since).elapsed())
    }

    /// True while more than the last write is unread (watch it closely).
    pub fn behind(&self) -> bool {
        self.stalled_since.is_some()
    }

    /// How long since the last write (none yet: zero).
    pub fn quiet_for(&self) -> Duration {
        self.last_at.map_or(Duration::ZERO, |t| t.elapsed())
    }
}

/// Byte offset of `tcpi_snd_wnd` in Linux's `struct tcp_info` (uapi
/// `linux/tcp.h`: after `tcpi_rcv_ooopack`).
#[cfg(target_os = "linux")]
const SND_WND_OFFSET: usize = 228;

/// The peer's advertised receive window (scaled), when the kernel reports it.
#[cfg(target_os = "linux")]
fn peer_window(stream: &TcpStream) -> Option<u32> {
    use std::os::fd::AsRawFd;
    let mut info = [0u8; 256];
    let mut len = info.len() as libc::socklen_t;
    // SAFETY: getsockopt on a socket this thread owns, into a live buffer of
    // `len` bytes; the kernel writes at most `len` and sets `len` to what it wrote.
    let rc = unsafe {
        libc::getsockopt(
            stream.as_raw_fd(),
            libc::IPPROTO_TCP,
            libc::TCP_INFO,
            info.as_mut_ptr().cast(),
            &mut len,
        )
    };
    let end = SND_WND_OFFSET + 4;
    if rc != 0 || (len as usize) < end {
        return None;
    }
    let bytes: [u8; 4] = info[SND_WND_OFFSET..end].try_into().ok()?;
    Some(u32::from_ne_bytes(bytes))
}

#[cfg(not(target_os = "linux"))]
fn peer_window(_: &TcpStream) -> Option<u32> {
    None
}

/// Sets the socket's send buffer (`SO_SNDBUF`); a failure leaves the default
/// (the write deadline still holds).
#[cfg(unix)]
pub fn set_send_buffer(stream: &TcpStream, bytes: usize) {
    use std::os::fd::AsRawFd;
    let value = bytes as libc::c_int;
    // SAFETY: setsockopt on a socket this thread owns, with a pointer to a live
    // c_int and its size. A failure (returned, not signalled) keeps the default.
    let _ = unsafe {
        libc::setsockopt(
            stream.as_raw_fd(),
            libc::SOL_SOCKET,
            libc::SO_SNDBUF,
            (&value as *const libc::c_int).cast(),
            std::mem::size_of::<libc::c_int>() as libc::socklen_t,
        )
    };
}

#[cfg(not(unix))]
pub fn set_send_buffer(_: &TcpStream, _: usize) {}
