//! The tuning server's HTTP request parsing (request line, headers, `Content-Length` body).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = sillage::tune::http::read_request(data);
});
