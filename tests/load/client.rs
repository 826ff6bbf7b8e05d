//! A minimal loopback HTTP/1.1 client and a handle on the service process, for the load and
//! fault tests (raw sockets, so slow and broken clients can be played exactly).

use std::io::{BufRead, BufReader};
use std::net::SocketAddr;
use std::process::{Child, ExitStatus};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use serde_json::Value;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;

/// A running service process.
pub struct Server {
    pub addr: SocketAddr,
    pub child: Option<Child>,
    log: Arc<Mutex<String>>,
}

impl Server {
    /// Start the binary on a free port and wait until `/healthz` answers.
    pub async fn start(env: &[(&str, &str)]) -> Self {
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .map(|a| a.port())
            .expect("a free port");
        let mut child = crate::spawn(port, env);
        let log = Arc::new(Mutex::new(String::new()));
        if let Some(out) = child.stdout.take() {
            let log = Arc::clone(&log);
            std::thread::spawn(move || {
                for line in BufReader::new(out).lines().map_while(Result::ok) {
                    if let Ok(mut l) = log.lock() {
                        l.push_str(&line);
                        l.push('\n');
                    }
                }
            });
        }
        let addr: SocketAddr = format!("127.0.0.1:{port}").parse().expect("address");
        let t = Instant::now();
        while get(addr, "/healthz").await.is_err() {
            assert!(
                t.elapsed() < Duration::from_secs(20),
                "the service did not start"
            );
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        Self {
            addr,
            child: Some(child),
            log,
        }
    }

    /// Process id.
    pub fn pid(&self) -> u32 {
        self.child.as_ref().map_or(0, Child::id)
    }

    /// What the service logged so far.
    pub fn log(&self) -> String {
        // Give the reader thread a moment to catch up.
        std::thread::sleep(Duration::from_millis(100));
        self.log.lock().map(|l| l.clone()).unwrap_or_default()
    }

    /// Send SIGHUP (the service rereads its API keys file).
    pub fn hup(&self) {
        let _ = std::process::Command::new("kill")
            .args(["-HUP", &self.pid().to_string()])
            .status();
    }

    /// SIGTERM, then wait up to `limit` for the exit.
    pub async fn terminate_and_wait(mut self, limit: Duration) -> Option<ExitStatus> {
        let pid = self.pid();
        let _ = std::process::Command::new("kill")
            .args(["-TERM", &pid.to_string()])
            .status();
        let t = Instant::now();
        let mut child = self.child.take()?;
        while t.elapsed() < limit {
            if let Ok(Some(s)) = child.try_wait() {
                return Some(s);
            }
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
        let _ = child.kill();
        None
    }

    /// Stop the service (SIGTERM, then kill if it lingers).
    pub async fn stop(self) {
        let _ = self.terminate_and_wait(Duration::from_secs(30)).await;
    }
}

/// An answer.
pub struct Reply {
    pub status: u16,
    /// The response head (status line and headers), lowercase.
    pub head: String,
    pub body: Vec<u8>,
}

impl Reply {
    /// A header's value (`name` lowercase).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.head.lines().find_map(|l| {
            let (k, v) = l.split_once(':')?;
            (k.trim() == name).then(|| v.trim())
        })
    }

    /// The `queue` duration of the Server-Timing header [ms].
    pub fn queue_ms(&self) -> Option<f64> {
        self.header("server-timing")?
            .split(',')
            .find_map(|p| p.trim().strip_prefix("queue;dur="))?
            .parse()
            .ok()
    }

    pub fn json(&self) -> Value {
        serde_json::from_slice(&self.body).unwrap_or(Value::Null)
    }
    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }
}

async fn exchange(addr: SocketAddr, request: Vec<u8>) -> std::io::Result<Reply> {
    let mut s = TcpStream::connect(addr).await?;
    s.write_all(&request).await?;
    let mut buf = Vec::new();
    tokio::time::timeout(Duration::from_secs(120), s.read_to_end(&mut buf))
        .await
        .map_err(|_| std::io::Error::other("no answer within 120 s"))??;
    let text_end = buf
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .ok_or_else(|| std::io::Error::other("no response head"))?;
    let head = String::from_utf8_lossy(&buf[..text_end]).to_ascii_lowercase();
    let status = head
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| std::io::Error::other("no status"))?;
    Ok(Reply {
        status,
        head,
        body: buf[text_end + 4..].to_vec(),
    })
}

/// `GET path` on a fresh connection.
pub async fn get(addr: SocketAddr, path: &str) -> std::io::Result<Reply> {
    exchange(
        addr,
        format!("GET {path} HTTP/1.1\r\nhost: t\r\nconnection: close\r\n\r\n").into_bytes(),
    )
    .await
}

fn post_bytes(path: &str, body: &Value) -> Vec<u8> {
    request_bytes("POST", path, Some(body), None, false)
}

/// An HTTP/1.1 request: `body` as JSON, an optional bearer `token`, keep-alive or close.
pub fn request_bytes(
    method: &str,
    path: &str,
    body: Option<&Value>,
    token: Option<&str>,
    keep_alive: bool,
) -> Vec<u8> {
    let b = body
        .map(|b| serde_json::to_vec(b).expect("serializes"))
        .unwrap_or_default();
    let mut head = format!("{method} {path} HTTP/1.1\r\nhost: t\r\n");
    if body.is_some() {
        head.push_str(&format!(
            "content-type: application/json\r\ncontent-length: {}\r\n",
            b.len()
        ));
    }
    if let Some(t) = token {
        head.push_str(&format!("authorization: Bearer {t}\r\n"));
    }
    if !keep_alive {
        head.push_str("connection: close\r\n");
    }
    head.push_str("\r\n");
    let mut r = head.into_bytes();
    r.extend_from_slice(&b);
    r
}

/// A JSON POST of raw `body` bytes on a connection closed after the answer.
pub fn request_bytes_raw(method: &str, path: &str, body: &[u8]) -> Vec<u8> {
    let mut r = format!(
        "{method} {path} HTTP/1.1\r\nhost: t\r\ncontent-type: application/json\r\n\
         content-length: {}\r\nconnection: close\r\n\r\n",
        body.len()
    )
    .into_bytes();
    r.extend_from_slice(body);
    r
}

/// Send prepared request bytes on a fresh connection (closed after the answer).
pub async fn send(addr: SocketAddr, request: Vec<u8>) -> std::io::Result<Reply> {
    exchange(addr, request).await
}

/// A keep-alive connection that sends one request after another (as load generators do).
pub struct KeepAlive {
    addr: SocketAddr,
    stream: TcpStream,
    buf: Vec<u8>,
}

impl KeepAlive {
    pub async fn connect(addr: SocketAddr) -> std::io::Result<Self> {
        let stream = TcpStream::connect(addr).await?;
        stream.set_nodelay(true)?;
        Ok(Self {
            addr,
            stream,
            buf: Vec::new(),
        })
    }

    /// Send `request` and read one answer (its head and `content-length` bytes of body).
    ///
    /// Like the connection pools of HTTP client libraries (urllib3's `is_connection_dropped`,
    /// hyper-util's pool), a connection the server has already closed (idle past its keep-alive
    /// limit, announced in the `keep-alive: timeout=` header) is replaced before the request is
    /// sent, not written into.
    pub async fn exchange(&mut self, request: &[u8]) -> std::io::Result<Reply> {
        let mut probe = [0u8; 1];
        match self.stream.try_read(&mut probe) {
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
            Ok(n) if n > 0 => self.buf.extend_from_slice(&probe[..n]),
            // Closed by the server (Ok(0)) or reset: a fresh connection.
            _ => *self = Self::connect(self.addr).await?,
        }
        self.stream.write_all(request).await?;
        let mut chunk = [0u8; 16 * 1024];
        loop {
            if let Some(end) = self.buf.windows(4).position(|w| w == b"\r\n\r\n") {
                let head = String::from_utf8_lossy(&self.buf[..end]).to_ascii_lowercase();
                let len: usize = head
                    .lines()
                    .find_map(|l| l.strip_prefix("content-length:"))
                    .and_then(|v| v.trim().parse().ok())
                    .ok_or_else(|| std::io::Error::other("no content-length"))?;
                while self.buf.len() < end + 4 + len {
                    let n = self.read(&mut chunk).await?;
                    self.buf.extend_from_slice(&chunk[..n]);
                }
                let body = self.buf[end + 4..end + 4 + len].to_vec();
                self.buf.drain(..end + 4 + len);
                let status = head
                    .split_whitespace()
                    .nth(1)
                    .and_then(|s| s.parse().ok())
                    .ok_or_else(|| std::io::Error::other("no status"))?;
                return Ok(Reply { status, head, body });
            }
            let n = self.read(&mut chunk).await?;
            self.buf.extend_from_slice(&chunk[..n]);
        }
    }

    async fn read(&mut self, chunk: &mut [u8]) -> std::io::Result<usize> {
        let n = tokio::time::timeout(Duration::from_secs(60), self.stream.read(chunk))
            .await
            .map_err(|_| std::io::Error::other("no answer within 60 s"))??;
        if n == 0 {
            return Err(std::io::Error::other("connection closed"));
        }
        Ok(n)
    }
}

/// The `q` quantile of `samples` (sorted in place), 0 when empty.
pub fn quantile(samples: &mut [f64], q: f64) -> f64 {
    if samples.is_empty() {
        return 0.0;
    }
    samples.sort_by(f64::total_cmp);
    let i = ((samples.len() as f64 - 1.0) * q).round() as usize;
    samples[i.min(samples.len() - 1)]
}

/// `POST path` with a JSON body on a fresh connection.
pub async fn post(addr: SocketAddr, path: &str, body: &Value) -> std::io::Result<Reply> {
    exchange(addr, post_bytes(path, body)).await
}

/// Send a request head one byte every `interval`, `bytes` bytes at most; true when the server
/// closed the connection before the head was complete.
pub async fn slowloris(addr: SocketAddr, interval: Duration, bytes: usize) -> bool {
    let Ok(mut s) = TcpStream::connect(addr).await else {
        return true;
    };
    let head = b"POST /v1/cam-law/evaluate HTTP/1.1\r\nhost: t\r\ncontent-type: application/json\r\nx-padding: ";
    for i in 0..bytes {
        let byte = head.get(i).copied().unwrap_or(b'a');
        if s.write_all(&[byte]).await.is_err() {
            return true;
        }
        tokio::time::sleep(interval).await;
        if is_closed(&mut s).await {
            return true;
        }
    }
    false
}

/// Whether the peer has closed the connection (EOF or reset), without waiting.
pub async fn is_closed(s: &mut TcpStream) -> bool {
    let mut b = [0u8; 512];
    match tokio::time::timeout(Duration::from_millis(1), s.read(&mut b)).await {
        Ok(Ok(0) | Err(_)) => true,
        Ok(Ok(_)) | Err(_) => false,
    }
}

/// Send a request with a large answer and do not read it for 3 s; then read what is there:
/// true when the server gave up on the connection (the answer is cut short).
pub async fn post_and_never_read(addr: SocketAddr, path: &'static str, body: Value) -> bool {
    let Ok(mut s) = TcpStream::connect(addr).await else {
        return false;
    };
    if s.write_all(&post_bytes(path, &body)).await.is_err() {
        return false;
    }
    tokio::time::sleep(Duration::from_secs(3)).await;
    let mut buf = Vec::new();
    let read = tokio::time::timeout(Duration::from_secs(20), s.read_to_end(&mut buf)).await;
    let Some(end) = buf.windows(4).position(|w| w == b"\r\n\r\n") else {
        return true;
    };
    let head = String::from_utf8_lossy(&buf[..end]).to_ascii_lowercase();
    let declared: usize = head
        .lines()
        .find_map(|l| l.strip_prefix("content-length: "))
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(usize::MAX);
    matches!(read, Ok(Err(_))) || buf.len() - end - 4 < declared
}

/// Resident memory of a process [KiB].
pub fn rss_kib(pid: u32) -> u64 {
    status_field(pid, "VmRSS:")
}

/// CPU time a process has used so far (user + system) [s], from `/proc/<pid>/stat` (clock ticks
/// of 10 ms).
pub fn cpu_seconds(pid: u32) -> f64 {
    let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
        return 0.0;
    };
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// Threads of a process, from `/proc/<pid>/status`.
pub fn thread_count(pid: u32) -> u64 {
    status_field(pid, "Threads:")
}

/// The first number of a `/proc/<pid>/status` line (0 when absent).
pub fn status_field(pid: u32, key: &str) -> u64 {
    std::fs::read_to_string(format!("/proc/{pid}/status"))
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix(key))
                .and_then(|v| v.split_whitespace().next()?.parse().ok())
        })
        .unwrap_or(0)
}

/// Raise this test process's descriptor limit (it opens thousands of connections).
pub fn raise_fd_limit() {
    let _ = rlimit::increase_nofile_limit(u64::MAX);
}
