//! A static file server for `web/`.
//!
//! Written by hand (about 80 lines of std) rather than pulling an async HTTP stack into the
//! build tool: it serves a handful of local files to one browser.

use crate::config::WebBuild;
use crate::setup;
use crate::util::{Result, root};
use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Component, Path, PathBuf};

/// Sets up, builds the page and serves it until interrupted.
pub fn run(port: u16) -> Result<()> {
    let installed = setup::ensure(false)?;
    setup::print_installed(&installed);
    WebBuild::load()?.build()?;
    let listener = bind(port)?;
    println!("Dupin configurator: http://127.0.0.1:{port}/  (Ctrl-C to stop)");
    serve_forever(listener, root().join("web"));
    Ok(())
}

/// Binds 127.0.0.1:`port` (0 picks a free port).
pub fn bind(port: u16) -> Result<TcpListener> {
    TcpListener::bind(("127.0.0.1", port))
        .map_err(|e| format!("cannot listen on 127.0.0.1:{port}: {e} (try --port)"))
}

/// Serves files under `dir`, one thread per connection.
pub fn serve_forever(listener: TcpListener, dir: PathBuf) {
    for stream in listener.incoming().flatten() {
        let dir = dir.clone();
        std::thread::spawn(move || {
            let _ = handle(stream, &dir);
        });
    }
}

/// The page loads everything from its own origin: scripts and the wasm module ('wasm-unsafe-eval'
/// lets WebAssembly compile, nothing else evaluates strings), its worker, styles and data or blob
/// images and reads (snapshots); no plugin, no frame, no form target, no base URL from outside.
const CSP: &str = "default-src 'self'; script-src 'self' 'wasm-unsafe-eval'; worker-src 'self'; \
                   connect-src 'self' data: blob:; img-src 'self' data: blob:; style-src 'self'; \
                   object-src 'none'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'";

/// The .3dm worker's own policy: rhino3dm's bindings (embind) build functions from strings, so
/// this worker alone may evaluate them; it loads rhino3dm's script and wasm from the origin and
/// nothing else.
const RHINO_WORKER_CSP: &str = "default-src 'none'; script-src 'self' 'unsafe-eval' \
                                'wasm-unsafe-eval'; connect-src 'self'";

/// The page's policy for `path`, a request path.
fn csp_for(path: &str) -> &'static str {
    if path == "/rhino-worker.js" {
        RHINO_WORKER_CSP
    } else {
        CSP
    }
}

fn handle(mut stream: TcpStream, dir: &Path) -> std::io::Result<()> {
    let mut reader = BufReader::new(stream.try_clone()?);
    let mut request = String::new();
    reader.read_line(&mut request)?;
    // Drain the headers; we need none of them.
    let mut line = String::new();
    while reader.read_line(&mut line)? > 2 {
        line.clear();
    }
    let mut parts = request.split_whitespace();
    let (method, target) = (parts.next().unwrap_or(""), parts.next().unwrap_or("/"));
    let path = target.split(['?', '#']).next().unwrap_or("/");
    let rel = Path::new(path.trim_start_matches('/'));
    let safe = rel.components().all(|c| matches!(c, Component::Normal(_)));
    let mut file = dir.join(rel);
    if file.is_dir() {
        file = file.join("index.html");
    }
    let (status, body, mime) = match (method, safe, std::fs::read(&file)) {
        ("GET" | "HEAD", true, Ok(body)) => ("200 OK", body, mime(&file)),
        ("GET" | "HEAD", _, _) => ("404 Not Found", b"not found".to_vec(), "text/plain"),
        _ => ("405 Method Not Allowed", Vec::new(), "text/plain"),
    };
    write!(
        stream,
        "HTTP/1.1 {status}\r\nContent-Type: {mime}\r\nContent-Length: {}\r\n\
         Content-Security-Policy: {}\r\nX-Content-Type-Options: nosniff\r\n\
         Cache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len(),
        csp_for(path),
    )?;
    if method != "HEAD" {
        stream.write_all(&body)?;
    }
    stream.flush()
}

fn mime(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()) {
        Some("html") => "text/html; charset=utf-8",
        Some("js" | "mjs") => "text/javascript; charset=utf-8",
        Some("css") => "text/css; charset=utf-8",
        Some("wasm") => "application/wasm",
        Some("json") => "application/json",
        Some("png") => "image/png",
        Some("svg") => "image/svg+xml",
        Some("ts") => "text/plain; charset=utf-8",
        _ => "application/octet-stream",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_rhino_worker_may_evaluate_strings() {
        assert!(csp_for("/rhino-worker.js").contains("'unsafe-eval'"));
        for path in ["/", "/index.html", "/worker.js", "/main.js", "/rhino.js"] {
            assert!(!csp_for(path).contains("'unsafe-eval'"), "{path}");
        }
    }
}
