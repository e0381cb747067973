//! How large an image lumis agrees to decode.
//!
//! An image file states its size in a header of a few bytes, and a
//! decoder allocates what the header claims before it reads a pixel: a
//! 74-byte PNG can claim 100000 x 100000 pixels and ask for 30 GB. Every
//! decoder of lumis checks the claim first, against a limit on pixels (as
//! Pillow's `MAX_IMAGE_PIXELS` does) and, where the format bounds how far
//! it compresses, against the file's own size.

/// The environment variable that sets the limit, in pixels.
pub const MAX_IMAGE_PIXELS_VAR: &str = "LUMIS_MAX_IMAGE_PIXELS";

/// The default limit: 2^28 pixels, a 16384 x 16384 image (3 GiB as float
/// RGB), above the 16k x 8k environment maps production scenes use.
pub const DEFAULT_MAX_IMAGE_PIXELS: u64 = 1 << 28;

/// The most a deflate stream expands: 258 bytes from a code of one bit
/// and a distance of one, 1032:1 at best (RFC 1951; zlib's technical
/// details give the same bound). A PNG's pixels are deflated, so they take
/// at most this many times its file's bytes.
pub const DEFLATE_MAX_RATIO: u64 = 1032;

/// The limit in force: [`MAX_IMAGE_PIXELS_VAR`] if set, else
/// [`DEFAULT_MAX_IMAGE_PIXELS`].
pub fn max_image_pixels() -> Result<u64, String> {
    match std::env::var(MAX_IMAGE_PIXELS_VAR) {
        Err(std::env::VarError::NotPresent) => Ok(DEFAULT_MAX_IMAGE_PIXELS),
        Ok(text) => parse_limit(&text),
        Err(e) => Err(format!("{MAX_IMAGE_PIXELS_VAR}: {e}")),
    }
}

fn parse_limit(text: &str) -> Result<u64, String> {
    text.trim()
        .parse::<u64>()
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| {
            format!("{MAX_IMAGE_PIXELS_VAR}={text:?}: expected a positive whole number of pixels")
        })
}

/// Refuses an image whose `format` header claims more than
/// [`max_image_pixels`] (the caller names the file).
pub fn check_claimed_size(format: &str, width: u64, height: u64) -> Result<(), String> {
    check_claimed_pixels(
        &format!("its {format} header claims {width} x {height} pixels"),
        width.saturating_mul(height),
    )
}

/// Refuses `pixels` past [`max_image_pixels`]; `claim` says who claims
/// them (`its EXR header claims 3 layers`).
pub fn check_claimed_pixels(claim: &str, pixels: u64) -> Result<(), String> {
    within(claim, pixels, max_image_pixels()?)
}

fn within(claim: &str, pixels: u64, limit: u64) -> Result<(), String> {
    if pixels > limit {
        return Err(format!(
            "{claim} ({pixels}), more than the {limit} lumis decodes; set \
             {MAX_IMAGE_PIXELS_VAR} to decode larger images"
        ));
    }
    Ok(())
}

/// Refuses a claim of `decoded` bytes of pixels from a `stored`-byte file
/// of a format that expands at most `max_ratio` times: the header is
/// damaged or forged.
pub fn check_expansion(
    format: &str,
    decoded: u64,
    stored: u64,
    max_ratio: u64,
) -> Result<(), String> {
    if decoded > stored.saturating_mul(max_ratio) {
        return Err(format!(
            "its {format} header claims {decoded} bytes of pixels in a {stored}-byte file, more \
             than its compression can hold ({max_ratio}:1): the file is damaged or forged"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn claims_past_the_limit_are_refused_with_both_numbers() {
        assert!(within("x", 1 << 28, 1 << 28).is_ok());
        let err = within(
            "its PNG header claims 100000 x 100000 pixels",
            10_000_000_000,
            1 << 28,
        )
        .unwrap_err();
        assert!(
            err.contains("100000 x 100000 pixels (10000000000), more than the 268435456")
                && err.contains(MAX_IMAGE_PIXELS_VAR),
            "{err}"
        );
    }

    #[test]
    fn the_limit_is_a_positive_whole_number() {
        assert_eq!(parse_limit(" 1000 "), Ok(1000));
        for bad in ["0", "-1", "1e6", "lots", ""] {
            let err = parse_limit(bad).unwrap_err();
            assert!(err.contains("positive whole number"), "{bad}: {err}");
        }
    }

    #[test]
    fn expansion_past_the_format_ratio_is_refused() {
        assert!(check_expansion("PNG", 1032 * 74, 74, DEFLATE_MAX_RATIO).is_ok());
        let err = check_expansion("PNG", 1032 * 74 + 1, 74, DEFLATE_MAX_RATIO).unwrap_err();
        assert!(
            err.contains("in a 74-byte file") && err.contains("1032:1"),
            "{err}"
        );
    }
}
