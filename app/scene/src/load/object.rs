//! The `[object]` table: the model, its placement, refraction and absorption.

use vitreous_optics::refraction::{Refraction, RefractionParseError};
use vitreous_optics::solid::Solid;

use super::*;

impl Loader<'_> {
    pub(super) fn object(&mut self, raw: &file::ObjectToml) -> Result<Object, SceneError> {
        let (model_path, bytes) = self.read_asset("object.model", &raw.model)?;
        let base = model_path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let model = mesh::load_gltf(&bytes, &base).map_err(|r| {
            self.src
                .asset(raw.model.span(), "object.model", &model_path, r)
        })?;
        for buffer in &model.buffers {
            self.hash_part("object.model buffer", buffer);
        }
        for warning in &model.warnings {
            tracing::warn!("{}: {warning}", model_path.display());
        }

        let (lo, hi) = model.mesh.bounds();
        let largest_extent = (hi - lo).max_element();
        let center_model = (lo + hi) / 2.0;
        let radius_model = model
            .mesh
            .positions
            .iter()
            .map(|p| p.distance(center_model))
            .fold(0.0f32, f32::max);
        if !(largest_extent > 0.0 && largest_extent.is_finite()) {
            return Err(self.src.asset(
                raw.model.span(),
                "object.model",
                &model_path,
                "the mesh has zero size",
            ));
        }

        let (scale, scale_field, scale_span) = match (&raw.diameter_m, &raw.scale) {
            (Some(d), Some(_)) => {
                return Err(self.src.invalid(
                    d.span(),
                    "object.diameter_m",
                    "give either `diameter_m` or `scale`, not both",
                ));
            }
            (Some(d), None) => {
                let d_m =
                    self.number("object.diameter_m", Some(d), 0.0, (0.0, 10.0), (true, true))?;
                if d_m >= 10.0 {
                    return Err(self.src.invalid(
                        d.span(),
                        "object.diameter_m",
                        format!("expected a number > 0 and < 10, found {d_m}"),
                    ));
                }
                (d_m / largest_extent, "object.diameter_m", d.span())
            }
            (None, Some(s)) => (
                self.number("object.scale", Some(s), 1.0, (0.0, 1.0e6), (true, false))?,
                "object.scale",
                s.span(),
            ),
            (None, None) => (1.0, "object.model", raw.model.span()),
        };
        let diameter_m = largest_extent * scale;
        if !(diameter_m > 0.0 && diameter_m < 10.0) {
            return Err(self.src.invalid(
                scale_span,
                scale_field,
                format!(
                    "the object would be {diameter_m} m across (model is {largest_extent} units \
                     across, scale {scale}); expected more than 0 and less than 10 m"
                ),
            ));
        }

        let position = self.vec3("object.position_m", &raw.position_m)?;
        let rotation = self.rotation("object.rotation_deg", raw.rotation_deg.as_ref())?;
        let world_from_model =
            Mat4::from_scale_rotation_translation(Vec3::splat(scale), rotation, position)
                * Mat4::from_translation(-center_model);

        let (ior, ior_source) = match (&raw.ior, model.ior) {
            (Some(n), _) => (
                self.number("object.ior", Some(n), 1.5, (1.0, 4.0), CLOSED)?,
                IorSource::Scene,
            ),
            (None, Some(n)) if (1.0..=4.0).contains(&n) => (n, IorSource::Gltf),
            (None, Some(n)) => {
                return Err(self.src.asset(
                    raw.model.span(),
                    "object.model",
                    &model_path,
                    format!("KHR_materials_ior is {n}; expected 1..=4 (or set `object.ior`)"),
                ));
            }
            (None, None) => (1.5, IorSource::Default),
        };

        let attenuation = self.attenuation(raw, model.volume, scale)?;

        let refraction = match &raw.refraction {
            None => Refraction::default(),
            Some(r) => r.get_ref().parse().map_err(|e: RefractionParseError| {
                self.src
                    .invalid(r.span(), "object.refraction", e.to_string())
            })?,
        };

        // Two-surface refraction follows the light through the glass's volume, which a mesh
        // that does not close (a cup modelled as one sheet) does not have; the renderer would
        // refuse it too, without naming the scene.
        if refraction == Refraction::TwoSurface
            && let Err(e) = Solid::new(
                &model.mesh.positions,
                &model.mesh.normals,
                &model.mesh.indices,
            )
        {
            return Err(self.src.asset(
                raw.model.span(),
                "object.model",
                &model_path,
                format!(
                    "two-surface refraction (`object.refraction`) follows the light through \
                     the object's volume: {e}"
                ),
            ));
        }

        let surface_texture = match &raw.surface_texture {
            Some(rel) => Some(self.photo("object.surface_texture", rel)?),
            None => None,
        };
        if surface_texture.is_none()
            && let Some(t) = &raw.surface_transmittance
        {
            return Err(self.src.invalid(
                t.span(),
                "object.surface_transmittance",
                "needs `object.surface_texture`",
            ));
        }
        let default_transmittance = if surface_texture.is_some() { 0.8 } else { 1.0 };
        let surface_transmittance = self.number(
            "object.surface_transmittance",
            raw.surface_transmittance.as_ref(),
            default_transmittance,
            (0.0, 1.0),
            CLOSED,
        )?;

        let mut object = Object {
            mesh: model.mesh,
            world_from_model,
            center_m: position,
            rotation,
            scale,
            model_center: center_model,
            radius_m: radius_model * scale,
            ior,
            ior_source,
            refraction,
            attenuation,
            surface_texture,
            surface_transmittance,
            model_path,
            lens: None,
        };
        object.lens = MeshLens::of(&object);
        Ok(object)
    }

    /// The object's absorption: the model's volume attenuation, its distance scaled from model
    /// units to metres with the object, each part overridden by the scene's.
    fn attenuation(
        &self,
        raw: &file::ObjectToml,
        volume: Option<VolumeAttenuation>,
        scale: f32,
    ) -> Result<Attenuation, SceneError> {
        let model = volume.map_or(Attenuation::NONE, |v| Attenuation {
            color: v.color,
            distance_m: v.distance * scale,
        });
        let distance_m = match &raw.attenuation_distance_m {
            Some(d) => self.number(
                "object.attenuation_distance_m",
                Some(d),
                0.0,
                (0.0, 1.0e6),
                (true, false),
            )?,
            None => model.distance_m,
        };
        let color = match &raw.attenuation_color {
            None => model.color,
            Some(c) => {
                let v = Vec3::from_array(self.array("object.attenuation_color", c)?);
                if !v.cmpge(Vec3::ZERO).all() || !v.cmple(Vec3::ONE).all() {
                    return Err(self.src.invalid(
                        c.span(),
                        "object.attenuation_color",
                        format!("expected linear RGB components in 0..=1, found {v}"),
                    ));
                }
                if distance_m.is_infinite() {
                    return Err(self.src.invalid(
                        c.span(),
                        "object.attenuation_color",
                        "needs `object.attenuation_distance_m` (the model gives no \
                         attenuationDistance)",
                    ));
                }
                v
            }
        };
        Ok(Attenuation { color, distance_m })
    }
}
