//! Reading glTF accessors: every element's bytes are checked to lie inside its buffer view and
//! buffer before they are read, so a broken file is an error, never a panic.

use gltf::accessor::{DataType, Dimensions};

/// The bytes of an accessor's elements: `(data, offset of element 0, stride, count)`,
/// after checking that every element lies inside its buffer view and buffer.
fn accessor_bytes<'b>(
    acc: &gltf::Accessor,
    buffers: &'b [Vec<u8>],
) -> Result<Option<(&'b [u8], usize)>, String> {
    if acc.sparse().is_some() {
        return Err(format!(
            "accessor {}: sparse accessors are not supported",
            acc.index()
        ));
    }
    let Some(view) = acc.view() else {
        return Ok(None);
    };
    let data = buffers
        .get(view.buffer().index())
        .ok_or_else(|| format!("accessor {}: buffer missing", acc.index()))?;
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&end| end <= data.len())
        .ok_or_else(|| {
            format!(
                "buffer view {} (bytes {}+{}) lies outside buffer {} ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                data.len()
            )
        })?;
    let view_bytes = &data[view.offset()..view_end];
    let elem = acc.size();
    let stride = view.stride().unwrap_or(elem);
    if stride < elem {
        return Err(format!(
            "accessor {}: byte stride {stride} is smaller than its element size {elem}",
            acc.index()
        ));
    }
    let count = acc.count();
    if count > 0 {
        let end = (count - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(acc.offset()))
            .and_then(|x| x.checked_add(elem));
        if end.is_none_or(|end| end > view_bytes.len()) {
            return Err(format!(
                "accessor {}: {count} elements of {elem} bytes (stride {stride}, offset {}) \
                 do not fit in buffer view {} ({} bytes)",
                acc.index(),
                acc.offset(),
                view.index(),
                view_bytes.len()
            ));
        }
    }
    Ok(Some((
        &view_bytes[acc.offset().min(view_bytes.len())..],
        stride,
    )))
}

fn component(data_type: DataType, bytes: &[u8], normalized: bool) -> Option<f32> {
    Some(match data_type {
        DataType::F32 => f32::from_le_bytes(bytes.get(..4)?.try_into().ok()?),
        DataType::U8 if normalized => f32::from(*bytes.first()?) / 255.0,
        DataType::U16 if normalized => {
            f32::from(u16::from_le_bytes(bytes.get(..2)?.try_into().ok()?)) / 65535.0
        }
        _ => return None,
    })
}

pub(super) fn read_floats<const N: usize>(
    acc: &gltf::Accessor,
    buffers: &[Vec<u8>],
    allow_normalized: bool,
) -> Result<Vec<[f32; N]>, String> {
    let dims_ok = matches!(
        (acc.dimensions(), N),
        (Dimensions::Vec2, 2) | (Dimensions::Vec3, 3)
    );
    let type_ok = acc.data_type() == DataType::F32
        || (allow_normalized
            && acc.normalized()
            && matches!(acc.data_type(), DataType::U8 | DataType::U16));
    if !dims_ok || !type_ok {
        return Err(format!(
            "accessor {} is {:?} of {:?}{}; expected VEC{N} of float",
            acc.index(),
            acc.dimensions(),
            acc.data_type(),
            if acc.normalized() {
                " (normalized)"
            } else {
                ""
            }
        ));
    }
    let count = acc.count();
    let Some((bytes, stride)) = accessor_bytes(acc, buffers)? else {
        return Ok(vec![[0.0; N]; count]);
    };
    let size = acc.data_type().size();
    let mut out = Vec::with_capacity(count);
    for i in 0..count {
        let mut v = [0.0f32; N];
        for (c, slot) in v.iter_mut().enumerate() {
            let at = i * stride + c * size;
            *slot = bytes
                .get(at..)
                .and_then(|b| component(acc.data_type(), b, acc.normalized()))
                .ok_or_else(|| format!("accessor {}: element {i} out of bounds", acc.index()))?;
            if !slot.is_finite() {
                return Err(format!(
                    "accessor {}: element {i} component {c} is {slot}, not a finite number",
                    acc.index()
                ));
            }
        }
        out.push(v);
    }
    Ok(out)
}

pub(super) fn read_indices(acc: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u32>, String> {
    if acc.dimensions() != Dimensions::Scalar
        || !matches!(
            acc.data_type(),
            DataType::U8 | DataType::U16 | DataType::U32
        )
    {
        return Err(format!(
            "accessor {} is {:?} of {:?}; expected SCALAR of unsigned byte, short or int",
            acc.index(),
            acc.dimensions(),
            acc.data_type()
        ));
    }
    let count = acc.count();
    let Some((bytes, stride)) = accessor_bytes(acc, buffers)? else {
        return Ok(vec![0; count]);
    };
    (0..count)
        .map(|i| {
            let at = i * stride;
            let b = bytes.get(at..).unwrap_or_default();
            let v = match acc.data_type() {
                DataType::U8 => b.first().map(|&x| u32::from(x)),
                DataType::U16 => b
                    .get(..2)
                    .map(|x| u32::from(u16::from_le_bytes([x[0], x[1]]))),
                _ => b
                    .get(..4)
                    .map(|x| u32::from_le_bytes([x[0], x[1], x[2], x[3]])),
            };
            v.ok_or_else(|| format!("accessor {}: element {i} out of bounds", acc.index()))
        })
        .collect()
}
