//! The live view's server: a thread accepting connections on the local
//! address, and a thread per connection, at most [`MAX_CONNECTIONS`] of
//! them. A connection's request head (read with `httparse`, at most
//! [`MAX_HEAD`] bytes within [`HEAD_TIME`]) asks for the page, which is
//! sent and the connection closed, or for the WebSocket at `/ws`, which
//! tungstenite takes over: state frames out as the robot runs, the
//! browser's requests in ([`super::protocol`]).
//!
//! Nothing a client does reaches the robot's loop but a request in a
//! bounded queue ([`super::Hub::request`]): a client that sends too much
//! is told its requests were dropped; one that does not read is dropped
//! when a frame cannot be written within [`WRITE_TIME`]; a message
//! larger than [`MAX_MESSAGE`] closes its connection; a connection past
//! the limit is answered 503 and closed. No async runtime: the robot's
//! loop is a plain thread, and so is each client's.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use tungstenite::protocol::WebSocketConfig;
use tungstenite::protocol::frame::CloseFrame;
use tungstenite::protocol::frame::coding::CloseCode;
use tungstenite::{Message, WebSocket};

use super::Hub;
use super::protocol::{self, Outgoing};

/// The most connections served at once (pages and WebSockets): past
/// them a connection is answered 503 and closed, so a flood of
/// connections costs a bounded number of threads.
pub(crate) const MAX_CONNECTIONS: usize = 32;

/// The longest request head read, bytes.
pub(crate) const MAX_HEAD: usize = 8192;

/// How long a client has to send its request head.
pub(crate) const HEAD_TIME: Duration = Duration::from_secs(5);

/// How long a frame may take to be written before the client is taken
/// to be one that does not read, and dropped.
pub(crate) const WRITE_TIME: Duration = Duration::from_secs(2);

/// The largest message a client may send, bytes (a command is a few).
pub(crate) const MAX_MESSAGE: usize = 16 * 1024;

/// How long a connection closed for a message too big reads (and
/// drops) the rest of it: closed with bytes unread, the socket would
/// answer with a TCP reset, and the client would lose the close frame
/// that says why.
const DRAIN_TIME: Duration = Duration::from_secs(5);

/// How often a connection looks for a new frame while waiting for its
/// client's messages.
const POLL: Duration = Duration::from_millis(15);

/// The page and what it loads, built into the binary: the view works
/// offline.
const PAGE: &str = include_str!("page.html");
const SCRIPT: &str = include_str!("page.js");
const STYLE: &str = include_str!("page.css");

/// Binds `address` and serves the view from a thread of its own.
/// Returns the address bound (port 0 asks for a free one).
pub(crate) fn start(address: SocketAddr, hub: Arc<Hub>) -> std::io::Result<SocketAddr> {
    let listener = TcpListener::bind(address)?;
    let bound = listener.local_addr()?;
    std::thread::Builder::new()
        .name("view-accept".into())
        .spawn(move || accept(&listener, &hub))?;
    Ok(bound)
}

fn accept(listener: &TcpListener, hub: &Arc<Hub>) {
    for stream in listener.incoming() {
        if hub.stopping() {
            return;
        }
        let Ok(stream) = stream else {
            // Out of descriptors, a connection reset before it was
            // taken: the next one may do.
            std::thread::sleep(Duration::from_millis(10));
            continue;
        };
        let Some(slot) = Slot::take(hub) else {
            hub.refused.fetch_add(1, Ordering::Relaxed);
            refuse(stream);
            continue;
        };
        let shared = Arc::clone(hub);
        let spawned = std::thread::Builder::new()
            .name("view-client".into())
            .spawn(move || {
                let _slot = slot;
                serve(stream, &shared);
            });
        if spawned.is_err() {
            hub.refused.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// A place among the [`MAX_CONNECTIONS`], given back when dropped.
struct Slot(Arc<Hub>);

impl Slot {
    fn take(hub: &Arc<Hub>) -> Option<Slot> {
        hub.connections
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |count| {
                (count < MAX_CONNECTIONS).then_some(count + 1)
            })
            .ok()
            .map(|_| Slot(Arc::clone(hub)))
    }
}

impl Drop for Slot {
    fn drop(&mut self) {
        self.0.connections.fetch_sub(1, Ordering::AcqRel);
    }
}

/// Answers a connection past the limit without reading it, at once.
fn refuse(mut stream: TcpStream) {
    let _ = stream.set_write_timeout(Some(Duration::from_millis(100)));
    let _ = stream.write_all(&response(
        "503 Service Unavailable",
        "text/plain; charset=utf-8",
        &format!("too many connections to the view (at most {MAX_CONNECTIONS})\n"),
        true,
    ));
}

/// An HTTP/1.1 response that closes the connection; without its body
/// (`with_body` false) for a HEAD, which is answered as a GET with the
/// same head, `Content-Length` included (RFC 9110, 9.3.2).
fn response(status: &str, kind: &str, body: &str, with_body: bool) -> Vec<u8> {
    // A 405 says which methods are served (RFC 9110, 15.5.6).
    let allow = if status.starts_with("405") {
        "Allow: GET, HEAD\r\n"
    } else {
        ""
    };
    format!(
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\n{allow}Cache-Control: no-store\r\nConnection: close\r\n\r\n{}",
        body.len(),
        if with_body { body } else { "" }
    )
    .into_bytes()
}

/// What a request head asks for.
#[derive(Debug, PartialEq)]
enum Asked {
    /// A file of the page (GET), by path.
    File(String),
    /// The WebSocket: the head is left unread for tungstenite.
    Socket,
    /// Something else: the status and a word to say why.
    Refused(&'static str, String),
}

/// Reads (peeks: a WebSocket's head stays for tungstenite's handshake)
/// the request head and says what it asks for, how long it is, and
/// whether the answer has a body (not for a HEAD).
fn read_head(stream: &TcpStream) -> (Asked, usize, bool) {
    let deadline = Instant::now() + HEAD_TIME;
    let mut buffer = vec![0u8; MAX_HEAD];
    let mut seen = 0;
    loop {
        let count = match stream.peek(&mut buffer) {
            Ok(0) => {
                return (
                    Asked::Refused("400 Bad Request", "no request".into()),
                    0,
                    true,
                );
            }
            Ok(count) => count,
            Err(error)
                if matches!(
                    error.kind(),
                    std::io::ErrorKind::WouldBlock
                        | std::io::ErrorKind::TimedOut
                        | std::io::ErrorKind::Interrupted
                ) =>
            {
                seen
            }
            Err(error) => {
                return (
                    Asked::Refused("400 Bad Request", error.to_string()),
                    0,
                    true,
                );
            }
        };
        let mut headers = [httparse::EMPTY_HEADER; 32];
        let mut request = httparse::Request::new(&mut headers);
        match request.parse(&buffer[..count]) {
            Ok(httparse::Status::Complete(length)) => {
                return (asked(&request), length, request.method != Some("HEAD"));
            }
            Ok(httparse::Status::Partial) if count >= MAX_HEAD => {
                return (
                    Asked::Refused(
                        "431 Request Header Fields Too Large",
                        format!("a request head longer than {MAX_HEAD} bytes"),
                    ),
                    0,
                    true,
                );
            }
            Ok(httparse::Status::Partial) => {}
            Err(error) => {
                return (
                    Asked::Refused("400 Bad Request", format!("not an HTTP request: {error}")),
                    0,
                    true,
                );
            }
        }
        if Instant::now() >= deadline {
            return (
                Asked::Refused(
                    "408 Request Timeout",
                    format!("no whole request head within {HEAD_TIME:?}"),
                ),
                0,
                true,
            );
        }
        if count == seen {
            // Peeking returns at once while bytes wait: give the rest of
            // the head time to come instead of spinning.
            std::thread::sleep(Duration::from_millis(5));
        }
        seen = count;
    }
}

fn asked(request: &httparse::Request<'_, '_>) -> Asked {
    let path = request.path.unwrap_or("/");
    let path = path.split('?').next().unwrap_or(path);
    if !matches!(request.method, Some("GET" | "HEAD")) {
        return Asked::Refused(
            "405 Method Not Allowed",
            format!(
                "{} is not served: the view answers GET and HEAD",
                request.method.unwrap_or("?")
            ),
        );
    }
    if let Some(refused) = foreign(request) {
        return refused;
    }
    let upgrade = request.headers.iter().any(|header| {
        header.name.eq_ignore_ascii_case("upgrade")
            && String::from_utf8_lossy(header.value).eq_ignore_ascii_case("websocket")
    });
    match (path, upgrade) {
        ("/ws", true) => Asked::Socket,
        ("/ws", false) => {
            Asked::Refused("426 Upgrade Required", "/ws is the view's WebSocket".into())
        }
        _ => Asked::File(path.to_owned()),
    }
}

/// A request from elsewhere than the user's own browser on this page: a
/// `Host` that is a name other than `localhost` (a DNS-rebinding page
/// names its own domain; an address, as typed or printed, is kept), or an
/// `Origin` other than the page's own (any web page the user has open may
/// open a WebSocket to a local port: it must not type to the robot).
/// Clients that send no `Origin` (not a browser) are served.
fn foreign(request: &httparse::Request<'_, '_>) -> Option<Asked> {
    let header = |name: &str| {
        request
            .headers
            .iter()
            .find(|header| header.name.eq_ignore_ascii_case(name))
            .map(|header| String::from_utf8_lossy(header.value).trim().to_owned())
    };
    // Two of either would have only the first checked (RFC 9112 asks a
    // server to refuse a second Host).
    for name in ["host", "origin"] {
        let count = request
            .headers
            .iter()
            .filter(|header| header.name.eq_ignore_ascii_case(name))
            .count();
        if count > 1 {
            return Some(Asked::Refused(
                "400 Bad Request",
                format!("a request with {count} {name} headers"),
            ));
        }
    }
    let Some(host) = header("host") else {
        return Some(Asked::Refused(
            "400 Bad Request",
            "a request without its Host".into(),
        ));
    };
    let name = host
        .rsplit_once(':')
        .filter(|(_, port)| port.chars().all(|c| c.is_ascii_digit()))
        .map_or(host.as_str(), |(name, _)| name);
    let name = name.trim_start_matches('[').trim_end_matches(']');
    if !(name.eq_ignore_ascii_case("localhost") || name.parse::<std::net::IpAddr>().is_ok()) {
        return Some(Asked::Refused(
            "403 Forbidden",
            format!("Host {host} is not this machine's address: open the address the view printed"),
        ));
    }
    match header("origin") {
        Some(origin) if !origin.eq_ignore_ascii_case(&format!("http://{host}")) => {
            Some(Asked::Refused(
                "403 Forbidden",
                format!("a page from {origin} may not drive the robot: open http://{host}/"),
            ))
        }
        _ => None,
    }
}

/// Serves one connection to its end.
fn serve(mut stream: TcpStream, hub: &Hub) {
    let _ = stream.set_nodelay(true);
    if stream.set_read_timeout(Some(POLL)).is_err()
        || stream.set_write_timeout(Some(WRITE_TIME)).is_err()
    {
        return;
    }
    let (asked, length, with_body) = read_head(&stream);
    let reply = match asked {
        Asked::Socket if with_body => {
            socket(stream, hub);
            return;
        }
        Asked::Socket => response(
            "426 Upgrade Required",
            "text/plain; charset=utf-8",
            "/ws is the view's WebSocket: GET it with an Upgrade\n",
            false,
        ),
        Asked::File(path) => match path.as_str() {
            "/" | "/index.html" => response("200 OK", "text/html; charset=utf-8", PAGE, with_body),
            "/page.js" => response(
                "200 OK",
                "text/javascript; charset=utf-8",
                SCRIPT,
                with_body,
            ),
            "/page.css" => response("200 OK", "text/css; charset=utf-8", STYLE, with_body),
            _ => response(
                "404 Not Found",
                "text/plain; charset=utf-8",
                &format!("{path}: not part of the view (open /)\n"),
                with_body,
            ),
        },
        Asked::Refused(status, why) => response(
            status,
            "text/plain; charset=utf-8",
            &format!("{why}\n"),
            with_body,
        ),
    };
    // The head is taken off the socket before the answer, so that
    // closing does not reset the connection under the client's read.
    let mut head = vec![0u8; length];
    let _ = stream.read_exact(&mut head);
    let _ = stream.write_all(&reply);
    let _ = stream.flush();
    let _ = stream.shutdown(std::net::Shutdown::Write);
}

/// The limits of a client's WebSocket.
fn config() -> WebSocketConfig {
    WebSocketConfig::default()
        .read_buffer_size(4096)
        .write_buffer_size(0)
        .max_write_buffer_size(1 << 20)
        .max_message_size(Some(MAX_MESSAGE))
        .max_frame_size(Some(MAX_MESSAGE))
}

/// A client's WebSocket: its requests to the hub, frames to it.
fn socket(stream: TcpStream, hub: &Hub) {
    let peer = stream
        .peer_addr()
        .map_or_else(|_| "a client".to_owned(), |a| a.to_string());
    // The handshake reads the head peeked above; the socket's short read
    // timeout would interrupt it, so it gets the head's whole time.
    let _ = stream.set_read_timeout(Some(HEAD_TIME));
    let mut socket = match tungstenite::accept_with_config(stream, Some(config())) {
        Ok(socket) => socket,
        Err(error) => {
            hub.say(&format!(
                "view: {peer}: the WebSocket handshake failed: {error}"
            ));
            return;
        }
    };
    if socket.get_ref().set_read_timeout(Some(POLL)).is_err() {
        return;
    }
    let mut client = protocol::Client::default();
    loop {
        if hub.stopping() {
            let _ = socket.close(None);
            let _ = socket.flush();
            return;
        }
        match socket.read() {
            Ok(Message::Text(text)) => {
                if let Some(reply) = hub.request(text.as_str()) {
                    if send(&mut socket, &reply).is_err() {
                        return;
                    }
                }
            }
            Ok(Message::Binary(_)) => {
                let reply = Outgoing::error("the view speaks JSON text messages, not binary ones");
                if send(&mut socket, &reply).is_err() {
                    return;
                }
            }
            Ok(_) => {}
            Err(tungstenite::Error::Io(error))
                if matches!(
                    error.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(tungstenite::Error::Capacity(error)) => {
                hub.say(&format!(
                    "view: {peer}: {error} (a message may be {MAX_MESSAGE} bytes); connection closed"
                ));
                let _ = send(
                    &mut socket,
                    &Outgoing::error(&format!(
                        "{error}: a message may be {MAX_MESSAGE} bytes; connection closed"
                    )),
                );
                // 1009 says why to the page (RFC 6455, 7.4.1); the reason
                // is at most 123 bytes.
                let _ = socket.close(Some(CloseFrame {
                    code: CloseCode::Size,
                    reason: format!("message too big: a message may be {MAX_MESSAGE} bytes").into(),
                }));
                let _ = socket.flush();
                drain(socket.get_mut());
                return;
            }
            Err(tungstenite::Error::Utf8(error)) => {
                // 1007: a text message that is not UTF-8 (RFC 6455, 7.4.1).
                hub.say(&format!(
                    "view: {peer}: a text message not UTF-8 ({error}); connection closed"
                ));
                let _ = socket.close(Some(CloseFrame {
                    code: CloseCode::Invalid,
                    reason: "a text message must be UTF-8 (JSON)".into(),
                }));
                let _ = socket.flush();
                drain(socket.get_mut());
                return;
            }
            Err(tungstenite::Error::ConnectionClosed | tungstenite::Error::AlreadyClosed) => {
                return;
            }
            Err(error) => {
                hub.say(&format!("view: {peer}: {error}; connection closed"));
                return;
            }
        }
        if let Some(message) = client.next(hub)
            && let Err(error) = send(&mut socket, &message)
        {
            // A client that closed is gone; one whose frames cannot be
            // written within WRITE_TIME is not reading.
            if let tungstenite::Error::Io(error) = error {
                hub.say(&format!(
                    "view: {peer}: not reading ({error}); connection dropped"
                ));
            }
            return;
        }
    }
}

/// Reads what the client still sends (the rest of a message too big, its
/// close frame) and drops it, until it stops sending for a moment, closes
/// or [`DRAIN_TIME`] has passed, then closes: the close frame sent before
/// reaches the client instead of a reset.
fn drain(stream: &mut TcpStream) {
    let deadline = Instant::now() + DRAIN_TIME;
    let _ = stream.set_read_timeout(Some(Duration::from_millis(200)));
    let mut buffer = [0u8; 16 * 1024];
    while Instant::now() < deadline {
        match stream.read(&mut buffer) {
            Ok(0) | Err(_) => break,
            Ok(_) => {}
        }
    }
    let _ = stream.shutdown(std::net::Shutdown::Both);
}

/// Sends `message`, flushed: an error if it cannot be written within
/// [`WRITE_TIME`].
fn send(socket: &mut WebSocket<TcpStream>, message: &Outgoing) -> tungstenite::Result<()> {
    socket.send(Message::text(message.to_json()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(head: &str) -> Asked {
        let mut headers = [httparse::EMPTY_HEADER; 32];
        let mut request = httparse::Request::new(&mut headers);
        assert!(matches!(
            request.parse(head.as_bytes()),
            Ok(httparse::Status::Complete(_))
        ));
        asked(&request)
    }

    #[test]
    fn heads_ask_for_the_page_the_socket_or_nothing() {
        assert_eq!(
            parse("GET /?x=1 HTTP/1.1\r\nHost: localhost\r\n\r\n"),
            Asked::File("/".into())
        );
        assert_eq!(
            parse(
                "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:80\r\nUpgrade: WebSocket\r\nConnection: Upgrade\r\n\r\n"
            ),
            Asked::Socket
        );
        assert!(matches!(
            parse("GET /ws HTTP/1.1\r\nHost: localhost:8\r\n\r\n"),
            Asked::Refused("426 Upgrade Required", _)
        ));
        assert!(matches!(
            parse("POST / HTTP/1.1\r\n\r\n"),
            Asked::Refused("405 Method Not Allowed", _)
        ));
    }

    /// The hostile tester's finding: any web page could drive the robot
    /// through the socket (cross-site WebSocket), or read the page by DNS
    /// rebinding.
    #[test]
    fn pages_from_elsewhere_are_refused() {
        let socket = "Upgrade: websocket\r\nConnection: Upgrade\r\n\r\n";
        assert_eq!(
            parse(&format!(
                "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:5\r\nOrigin: http://127.0.0.1:5\r\n{socket}"
            )),
            Asked::Socket
        );
        assert_eq!(
            parse(&format!("GET /ws HTTP/1.1\r\nHost: [::1]:5\r\n{socket}")),
            Asked::Socket
        );
        for head in [
            format!(
                "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:5\r\nOrigin: http://evil.example\r\n{socket}"
            ),
            format!(
                "GET /ws HTTP/1.1\r\nHost: evil.example\r\nOrigin: http://evil.example\r\n{socket}"
            ),
            "GET / HTTP/1.1\r\nHost: evil.example:5\r\n\r\n".to_owned(),
            "GET / HTTP/1.1\r\n\r\n".to_owned(),
            // Only the first of two was checked.
            format!("GET /ws HTTP/1.1\r\nHost: 127.0.0.1:5\r\nHost: evil.example\r\n{socket}"),
            format!(
                "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:5\r\nOrigin: http://127.0.0.1:5\r\nOrigin: http://evil.example\r\n{socket}"
            ),
        ] {
            assert!(
                matches!(
                    parse(&head),
                    Asked::Refused("403 Forbidden" | "400 Bad Request", _)
                ),
                "{head}"
            );
        }
    }
}
