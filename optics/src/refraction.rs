//! Which refraction model the glass uses (`[object] refraction` in a scene file): the paper's
//! one refraction at the front surface ([`crate::optics::refract_heckbert`]) or the path in and
//! out through both surfaces ([`crate::two_surface`]).

/// How the glass pass refracts the view ray (`[object] refraction` in a scene file).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Refraction {
    /// The paper's model (eq. 7-8): one refraction at the front surface, then straight on to
    /// the background. The reference for the paper's studies.
    #[default]
    Paper,
    /// In at the front and out at the back surface, with total internal reflection followed
    /// for a bounded number of bounces (docs/equations.md, *Beyond the paper*).
    TwoSurface,
}

impl Refraction {
    /// The name a scene file uses.
    pub fn name(self) -> &'static str {
        match self {
            Refraction::Paper => "paper",
            Refraction::TwoSurface => "two-surface",
        }
    }
}

/// A refraction model name that is neither `paper` nor `two-surface`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("expected \"paper\" or \"two-surface\", found \"{0}\"")]
pub struct RefractionParseError(pub String);

impl std::str::FromStr for Refraction {
    type Err = RefractionParseError;

    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        match s {
            "paper" => Ok(Refraction::Paper),
            "two-surface" => Ok(Refraction::TwoSurface),
            _ => Err(RefractionParseError(s.to_owned())),
        }
    }
}
