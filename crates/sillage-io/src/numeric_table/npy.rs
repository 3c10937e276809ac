//! NumPy's `.npy` format, version 1.0: the magic string, a little-endian u16 header length,
//! a Python-literal header dictionary padded with spaces to a multiple of 64 bytes, then the
//! records, each field little-endian in column order.

use super::{ColumnValues, NumericTable};

/// The whole file's bytes for `table` as a structured array of shape `(rows,)`.
pub(super) fn encode(table: &NumericTable) -> Vec<u8> {
    let fields: Vec<String> = table
        .columns()
        .iter()
        .map(|(name, values)| {
            let kind = match values {
                ColumnValues::Int(_) => "<i8",
                ColumnValues::Float(_) => "<f8",
            };
            format!("('{}', '{kind}')", name.replace(['\'', '\\'], "_"))
        })
        .collect();
    let mut header = format!(
        "{{'descr': [{}], 'fortran_order': False, 'shape': ({},), }}",
        fields.join(", "),
        table.rows()
    );
    // Magic (6) + version (2) + length (2) + header + newline: a multiple of 64.
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat(unpadded.next_multiple_of(64) - unpadded));
    header.push('\n');
    let mut bytes =
        Vec::with_capacity(10 + header.len() + table.rows() * 8 * table.columns().len());
    bytes.extend_from_slice(b"\x93NUMPY\x01\x00");
    // A header of many columns stays far below 64 KiB: names are short.
    bytes.extend_from_slice(
        &u16::try_from(header.len())
            .unwrap_or(u16::MAX)
            .to_le_bytes(),
    );
    bytes.extend_from_slice(header.as_bytes());
    for row in 0..table.rows() {
        for (_, values) in table.columns() {
            match values {
                ColumnValues::Int(v) => bytes.extend_from_slice(&v[row].to_le_bytes()),
                ColumnValues::Float(v) => bytes.extend_from_slice(&v[row].to_le_bytes()),
            }
        }
    }
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_is_aligned_and_records_follow() {
        let mut table = NumericTable::default();
        table.push("count", ColumnValues::Int(vec![7])).unwrap();
        table.push("u", ColumnValues::Float(vec![0.5])).unwrap();
        let bytes = encode(&table);
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0);
        let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
        assert!(header.starts_with("{'descr': [('count', '<i8'), ('u', '<f8')]"));
        assert!(header.contains("'shape': (1,)") && header.ends_with('\n'));
        let data = &bytes[10 + header_len..];
        assert_eq!(data.len(), 16);
        assert_eq!(i64::from_le_bytes(data[..8].try_into().unwrap()), 7);
        assert_eq!(f64::from_le_bytes(data[8..].try_into().unwrap()), 0.5);
    }
}
