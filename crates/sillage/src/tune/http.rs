//! The little HTTP/1.1 that the tuning page needs, on the standard library alone: one request
//! per connection (`Connection: close`), one thread per connection, bodies sized by
//! `Content-Length`, headers and bodies bounded so a stray client cannot exhaust memory.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::sync::Arc;
use std::time::Duration;

use serde::Serialize;

/// Longest request line plus headers accepted, bytes.
const MAX_HEAD_BYTES: u64 = 16 * 1024;
/// Largest request body accepted, bytes (a configuration is well under 10 kB).
const MAX_BODY_BYTES: usize = 1 << 20;
/// How long a connection may stay silent before it is dropped (browsers open spare ones).
const READ_TIMEOUT: Duration = Duration::from_secs(30);

/// One parsed request.
#[derive(Debug)]
pub struct Request {
    /// `GET`, `POST`, ...
    pub method: String,
    /// The path, without the query string.
    pub path: String,
    /// The body (empty without `Content-Length`).
    pub body: Vec<u8>,
}

/// One response, sent with its length and `Cache-Control: no-store` (every answer is live).
#[derive(Debug)]
pub struct Response {
    /// Status code.
    pub status: u16,
    /// `Content-Type` header.
    pub content_type: &'static str,
    /// The body.
    pub body: Vec<u8>,
}

impl Response {
    /// `200 OK` with `value` as JSON.
    pub fn json(value: &impl Serialize) -> Self {
        match serde_json::to_vec(value) {
            Ok(body) => Self::bytes("application/json", body),
            Err(e) => Self::error(500, format!("cannot encode the reply: {e}")),
        }
    }

    /// `200 OK` with `body` of type `content_type`.
    pub fn bytes(content_type: &'static str, body: Vec<u8>) -> Self {
        Self {
            status: 200,
            content_type,
            body,
        }
    }

    /// An error status with `{"error": message}`, which the page shows as it is.
    pub fn error(status: u16, message: impl Into<String>) -> Self {
        let body = serde_json::json!({ "error": message.into() }).to_string();
        Self {
            status,
            content_type: "application/json",
            body: body.into_bytes(),
        }
    }
}

/// Answers every connection of `listener` with `handler`, each on its own thread; returns only
/// if accepting fails.
pub fn serve(
    listener: &TcpListener,
    handler: Arc<dyn Fn(&Request) -> Response + Send + Sync>,
) -> std::io::Result<()> {
    loop {
        let (stream, _) = listener.accept()?;
        let handler = Arc::clone(&handler);
        std::thread::spawn(move || {
            // A client that goes away mid-request is not an error of the server.
            let _ = answer(stream, handler.as_ref());
        });
    }
}

/// Reads one request from `stream`, answers it and closes the connection.
fn answer(
    stream: TcpStream,
    handler: &(dyn Fn(&Request) -> Response + Send + Sync),
) -> std::io::Result<()> {
    stream.set_read_timeout(Some(READ_TIMEOUT))?;
    let mut writer = stream.try_clone()?;
    let response = match read_request(&stream) {
        Ok(Some(request)) => handler(&request),
        Ok(None) => return Ok(()),
        Err(response) => response,
    };
    write_response(&mut writer, &response)
}

/// Reads one request from `stream` (a connection, or any bytes): `Ok(None)` when the client
/// closed without sending one, `Err` with the 4xx answer when it is malformed or too large.
/// At most the head limit plus the body limit is read, whatever the stream holds.
pub fn read_request(stream: impl Read) -> Result<Option<Request>, Response> {
    let mut head = BufReader::new(stream.take(MAX_HEAD_BYTES));
    let mut line = String::new();
    match head.read_line(&mut line) {
        Ok(0) | Err(_) => return Ok(None),
        Ok(_) => {}
    }
    let mut parts = line.split_whitespace();
    let (Some(method), Some(target), Some(_version)) = (parts.next(), parts.next(), parts.next())
    else {
        return Err(Response::error(400, "malformed request line"));
    };
    let path = target.split('?').next().unwrap_or(target).to_string();
    let method = method.to_string();
    let mut content_length = 0usize;
    loop {
        let mut header = String::new();
        match head.read_line(&mut header) {
            Ok(0) => {
                return Err(Response::error(
                    431,
                    "request headers too large or cut short",
                ));
            }
            Ok(_) => {}
            Err(_) => return Ok(None),
        }
        let header = header.trim_end();
        if header.is_empty() {
            break;
        }
        if let Some((name, value)) = header.split_once(':')
            && name.trim().eq_ignore_ascii_case("content-length")
        {
            content_length = value
                .trim()
                .parse()
                .map_err(|_| Response::error(400, "malformed Content-Length"))?;
        }
    }
    if content_length > MAX_BODY_BYTES {
        return Err(Response::error(
            413,
            format!("request body of {content_length} bytes; at most {MAX_BODY_BYTES} accepted"),
        ));
    }
    // What the head reader buffered past the headers is the start of the body.
    let buffered = head.buffer().to_vec();
    let mut body = buffered;
    let mut rest = head.into_inner().into_inner();
    if body.len() < content_length {
        let start = body.len();
        body.resize(content_length, 0);
        rest.read_exact(&mut body[start..])
            .map_err(|_| Response::error(400, "request body shorter than its Content-Length"))?;
    }
    body.truncate(content_length);
    Ok(Some(Request { method, path, body }))
}

/// Writes `response` with its headers.
fn write_response(stream: &mut TcpStream, response: &Response) -> std::io::Result<()> {
    let reason = match response.status {
        200 => "OK",
        400 => "Bad Request",
        404 => "Not Found",
        405 => "Method Not Allowed",
        413 => "Payload Too Large",
        431 => "Request Header Fields Too Large",
        _ => "Internal Server Error",
    };
    write!(
        stream,
        "HTTP/1.1 {} {reason}\r\nContent-Type: {}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        response.status,
        response.content_type,
        response.body.len()
    )?;
    stream.write_all(&response.body)?;
    stream.flush()
}
