//! How the `vitreous` command prints an error: the error and its causes in one line.

/// The error and its causes in one line, outermost first, leaving out a cause whose text the
/// line already ends with (many errors quote their source in their own message).
pub fn error_text(error: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in error.chain() {
        let part = cause.to_string();
        if text.ends_with(part.as_str()) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&part);
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_text_leaves_out_causes_already_quoted() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let e = anyhow::Error::new(io)
            .context("reading a: no such file")
            .context("loading b");
        assert_eq!(error_text(&e), "loading b: reading a: no such file");
    }
}
