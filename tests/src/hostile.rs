//! What the hostile corpora (`tests/tests/hostile.rs`, `hostile_surfaces.rs`) send
//! to every key and check of every reply.

/// Garbage payloads, sent to every command: not objects, broken JSON, invalid
/// UTF-8, NaN and overflowing numbers, 100,000-deep nesting, 2 MiB of blanks, a
/// 2 MiB string, an unknown field, a position at 1e308.
pub fn garbage() -> Vec<Vec<u8>> {
    vec![
        b"[]".to_vec(),
        b"1".to_vec(),
        b"\"x\"".to_vec(),
        b"null".to_vec(),
        b"{".to_vec(),
        b"\xff\xfe".to_vec(),
        b"{\"a\":NaN}".to_vec(),
        b"{\"mass\":1e400}".to_vec(),
        "[".repeat(100_000).into_bytes(),
        vec![b'{'; 50_000],
        vec![b' '; 1 << 21],
        format!("{{\"x\":\"{}\"}}", "a".repeat(2 << 20)).into_bytes(),
        br#"{"unknown": 1}"#.to_vec(),
        br#"{"pose": {"position": [1e308, 0, 0], "quaternion": [0,0,0,1]}}"#.to_vec(),
    ]
}

/// A successful reply must be a JSON object; an error reply must not be
/// `internal` or `plugin_panicked` (the client turns an error payload that is not
/// the common error object into `internal`).
pub fn check_well_formed(case: &str, reply: &Result<String, String>) {
    match reply {
        Ok(text) => {
            let v: serde_json::Value = serde_json::from_str(text)
                .unwrap_or_else(|e| panic!("{case}: reply is not JSON ({e}): {text:.300}"));
            assert!(v.is_object(), "{case}: reply is not an object: {text:.300}");
        }
        Err(text) => {
            let v: serde_json::Value = serde_json::from_str(text).unwrap();
            let code = v["error"]["code"].as_str().unwrap_or_default();
            assert!(
                !code.is_empty() && code != "internal" && code != "plugin_panicked",
                "{case}: error reply {text:.300}"
            );
        }
    }
}
