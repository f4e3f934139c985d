//! Text decoding of mesh files (OBJ, MTL), shared by the readers.

/// The text of a file that may be UTF-8 (with or without a byte-order
/// mark), UTF-16 with a byte-order mark, or else Latin-1 (ISO 8859-1, as
/// older exporters write accented names): every byte is then the code
/// point of the same value, so nothing is lost or refused.
pub fn decode_text(bytes: &[u8]) -> String {
    if let Some(rest) = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF])
        && let Ok(t) = std::str::from_utf8(rest)
    {
        return t.to_string();
    }
    let utf16 = |be: bool| {
        let units: Vec<u16> = bytes[2..]
            .chunks_exact(2)
            .map(|c| {
                if be {
                    u16::from_be_bytes([c[0], c[1]])
                } else {
                    u16::from_le_bytes([c[0], c[1]])
                }
            })
            .collect();
        String::from_utf16(&units).ok()
    };
    let decoded = match bytes {
        [0xFE, 0xFF, ..] => utf16(true),
        [0xFF, 0xFE, ..] => utf16(false),
        _ => None,
    };
    if let Some(t) = decoded {
        return t;
    }
    match std::str::from_utf8(bytes) {
        Ok(t) => t.to_string(),
        Err(_) => bytes.iter().map(|&b| b as char).collect(),
    }
}
