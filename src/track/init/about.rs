//! Steps 3 and 4 of `bulge init` about one axis: the clamp ring (and
//! through it the camera's roll, elevation and distance), then the scale
//! from the opening's sides and the axis they give. `init` reads them
//! about step 2's axis, and again about the sides' when the two lie more
//! than a pixel apart.

use super::clamp::Hint;
use super::*;

/// What steps 3 and 4 find about an axis: the clamp ring, the camera's
/// roll, elevation and distance, the scale from the opening, and the axis
/// the opening's sides give.
pub(super) struct RingAndScale {
    /// The clamp ring, placed (through the pinhole when the distance is
    /// known).
    pub(super) clamp: Clamp,
    /// The camera's roll about its view axis, degrees.
    pub(super) roll_deg: Estimate,
    /// The camera's elevation above the clamp plane, degrees.
    pub(super) elevation_deg: Option<Estimate>,
    /// The camera's distance from the axis, m, given or found from the
    /// lens's focal length.
    pub(super) camera_distance_m: Option<f64>,
    /// The lens's focal length, px, when the distance was found from it.
    pub(super) focal_px: Option<f64>,
    /// The sine of the elevation (0 below the plane).
    pub(super) sin_e: f64,
    /// `d ln(mpp) / d c`: the scale's change per px of the clamp row.
    pub(super) scale_per_clamp_row: f64,
    /// The opening's half-width, px (`None` when the scale is given).
    pub(super) radius_px: Option<Estimate>,
    /// The scale at the clamp ring's centre, m per px.
    pub(super) metres_per_pixel: Estimate,
    /// Where the scale came from.
    pub(super) scale_from: ScaleSource,
    /// The points located on the opening's sides, `[column, row]`.
    pub(super) side_points_px: Vec<[f64; 2]>,
    /// The axis's column from the sides (step 2's when they are not read).
    pub(super) axis_x_px: Estimate,
}

/// What steps 3 and 4 read from: the photos' planes and what the steps
/// before found or were given.
pub(super) struct Steps34<'a> {
    /// The mean of every photo in the clamp's rows, of the first and the
    /// last elsewhere.
    pub(super) mean: &'a Plane,
    /// The last photo.
    pub(super) last: &'a Plane,
    /// The opening's half-width from the swept band, px.
    pub(super) a0: f64,
    /// The swept band's lowest row and the row where the last photo's
    /// sides meet the clamp, px: where the clamp's top edge is searched.
    pub(super) rows: [f64; 2],
    /// What the clamp's search knows beforehand.
    pub(super) hint: Hint,
    /// What is given instead of found.
    pub(super) given: Given,
    /// The principal point's row, px.
    pub(super) principal_row: f64,
    /// The specimen's free radius `a`, m.
    pub(super) radius_m: f64,
    /// The last photo's apex row, px.
    pub(super) top: f64,
    /// The camera's tone curve.
    pub(super) tone: crate::track::image::Tone,
    /// The standard error of step 2's axis, px.
    pub(super) x0_std: f64,
}

impl Steps34<'_> {
    /// Steps 3 and 4 about the axis at column `x0`: the ring's ends are
    /// taken when they are mirrored about it, and the pinhole is placed on
    /// it.
    pub(super) fn read(&self, x0: f64) -> Result<RingAndScale, TrackError> {
        let Steps34 {
            mean,
            last,
            a0,
            rows,
            hint,
            given,
            principal_row,
            radius_m,
            top,
            tone,
            x0_std,
        } = *self;
        // A clamp row given is taken as it is: the camera not rolled, its
        // elevation the one given (level without it).
        let (clamp, (roll_deg, elevation_deg)) = match given.clamp_row_px {
            Some(row) => {
                let clamp = Clamp::given(row, x0, given.lens.as_ref(), top, mean.h)?;
                let e = given.elevation_deg.map(|e| Estimate { value: e, std: 0.0 });
                (
                    clamp,
                    (
                        Estimate {
                            value: 0.0,
                            std: 0.0,
                        },
                        e,
                    ),
                )
            }
            None => {
                let clamp = find_clamp(mean, x0, a0, rows, hint, given.lens.as_ref())?;
                let checked = clamp.checked(rows[0], given.elevation_deg)?;
                (clamp, checked)
            }
        };
        // A pinhole camera at a known distance: the ring's centre row and the
        // elevation from the ring's far side seen through it, the scale from
        // the opening's tangent points (twice: each depends on the other).
        let mut clamp = clamp;
        let mut elevation_deg = elevation_deg;
        // Without the distance, a calibrated lens gives it: the scale at the
        // ring's centre is the slant distance over the focal length
        // ([`ring::distance_from_focal`]), so the distance follows from the
        // scale found, and is found again with it.
        let focal_px = given
            .lens
            .as_ref()
            .filter(|_| given.camera_distance_m.is_none() && given.distance_from_focal)
            .map(|l| l.fy);
        let distance_of = |f: f64, mpp: f64, e: Option<Estimate>, row: f64| {
            let e = e.map_or(0.0, |e| e.value.to_radians());
            ring::distance_from_focal(f, e, row, mpp, principal_row)
        };
        let mut camera_distance_m = given.camera_distance_m.or_else(|| {
            let mpp = given.metres_per_pixel.unwrap_or(radius_m / a0);
            focal_px.map(|f| distance_of(f, mpp, elevation_deg, clamp.row.value))
        });
        // The opening's half-width from the sides, less the bias of their extrapolation measured
        // on the neo-Hookean dome as high as the last photo's, through the camera
        // ([`meridian::unbiased`]; through a pinhole the bias changes by 0.3 px for 0.02 a of
        // height at 0.25 m and 5 degrees, so the height is the pinhole's).
        let e_of = |e: Option<Estimate>| e.map_or(0.0, |e| e.value.to_radians());
        let unbiased = |o: &scale::Opening, d: Option<f64>, e: f64, mpp: f64, row: f64| {
            let p = d.map(|d| ring::camera(d, e, row, mpp, x0, principal_row));
            let h_over_a = match &p {
                Some(p) => p
                    .membrane_height(top, 0.0, radius_m, None)
                    .map_or(f64::NAN, |h| h.0 / radius_m),
                None => (row - top) / e.cos() / a0,
            };
            let domes = meridian::Meridian::domes(h_over_a);
            let view = p
                .as_ref()
                .map_or(meridian::View::Orthographic, meridian::View::Pinhole);
            let sin_e = e.max(0.0).sin();
            let at = meridian::Reading {
                radius_m,
                mpp,
                c: row,
                sin_e,
                a0,
            };
            meridian::unbiased(o, domes.as_ref(), view, &at)
        };
        // Step 4's sides, read in the photo's rows: through a lens the
        // clamp row where they meet it is the photo's, not the undistorted
        // image's.
        let read_sides = |clamp: &Clamp, sin_e: f64| {
            let mut in_photo = clamp.clone();
            in_photo.row.value = crate::track::lens::clamp_row_at_sides(
                given.lens.as_ref(),
                x0,
                a0,
                clamp.row.value,
            );
            find_radius(last, x0, a0, &in_photo, sin_e, tone)
        };
        if let Some(mut d) = camera_distance_m {
            let mut mpp = given.metres_per_pixel.unwrap_or(radius_m / a0);
            let rounds = if focal_px.is_some() { 5 } else { 2 };
            for _ in 0..rounds {
                if !(d.is_finite() && d > 2.0 * radius_m) {
                    return Err(TrackError::NotFound {
                        what: "the camera's distance".into(),
                        detail: format!(
                            "the lens's focal length {:.1} px and the scale {mpp:.4e} m/px put the camera {d:.4} m from the axis, within the opening's diameter: the lens was calibrated at another zoom or photo size; or give the distance ({})",
                            focal_px.unwrap_or(f64::NAN),
                            crate::setting::Setting::CameraDistance
                        ),
                        keys: "[camera] distance_m",
                        clamp_plane: false,
                    });
                }
                let at = ring::View {
                    d,
                    mpp,
                    x0,
                    principal_row,
                };
                ring::place_ring(&mut clamp, &mut elevation_deg, &at, radius_m)?;
                if given.metres_per_pixel.is_none() {
                    let e = elevation_deg.map_or(0.0, |e| e.value.to_radians());
                    let o = read_sides(&clamp, e.max(0.0).sin())?;
                    let a = unbiased(&o, Some(d), e, mpp, clamp.row.value).value;
                    // in the undistorted image, as the scale at the end of step 4
                    let a = crate::track::lens::undistort_opening(
                        given.lens.as_ref(),
                        x0,
                        clamp.row.value,
                        Some(a),
                    )
                    .1
                    .unwrap_or(a);
                    mpp = ring::centre_scale(radius_m, a, d, e, clamp.row.value, x0, principal_row);
                }
                if let Some(f) = focal_px {
                    d = distance_of(f, mpp, elevation_deg, clamp.row.value);
                }
            }
            camera_distance_m = Some(d);
        }
        let sin_e = elevation_deg.map_or(0.0, |e| e.value.max(0.0).to_radians().sin());

        // Step 4: the scale (`d ln(mpp) / d c = -(d a / d c) / a`).
        let mut scale_per_clamp_row = 0.0;
        let (radius_px, metres_per_pixel, scale_from, side_points_px) = match given.metres_per_pixel
        {
            Some(m) => (
                None,
                Estimate { value: m, std: 0.0 },
                ScaleSource::Given,
                Vec::new(),
            ),
            None => {
                let o = read_sides(&clamp, sin_e)?;
                let e = e_of(elevation_deg);
                let scale_of = |a: f64| match camera_distance_m {
                    Some(d) => {
                        ring::centre_scale(radius_m, a, d, e, clamp.row.value, x0, principal_row)
                    }
                    None => radius_m / a,
                };
                // The bias is measured through the camera of the scale it
                // leaves: three rounds reach that fixed point.
                let mut a = o.a;
                for _ in 0..3 {
                    a = unbiased(&o, camera_distance_m, e, scale_of(a.value), clamp.row.value);
                }
                // An opening whose width cannot be told from none at the
                // 95 % level (1.96 of its deviations) is not measured: the
                // sides read above the clamp row do not close into one
                // there, so that row is most likely not the clamp plane.
                if a.value < 1.96 * a.std {
                    return Err(TrackError::NotFound {
                        what: "the bubble's opening at the clamp plane".into(),
                        detail: format!(
                            "the bubble's sides above the clamp row found ({:.1} +- {:.1} px) extrapolate to an opening 2a = {:.1} +- {:.1} px wide there, which cannot be told from none: that row is most likely not the clamp plane (another edge across the ring, a lit floor or table behind it); open the photos to find the clamp's top edge",
                            clamp.row.value,
                            clamp.row.std,
                            2.0 * a.value,
                            2.0 * a.std
                        ),
                        keys: "clamp_row_px, or the scale (metres_per_pixel)",
                        clamp_plane: true,
                    });
                }
                let sides = o.sides;
                let mpp = scale_of(a.value);
                scale_per_clamp_row = -o.per_clamp_row / a.value;
                (
                    Some(a),
                    Estimate {
                        value: mpp,
                        std: mpp * a.std / a.value,
                    },
                    ScaleSource::ClampOpening,
                    sides,
                )
            }
        };

        // The axis: the mean midpoint of the sides where they were located.
        let axis_x_px = scale::axis_from_sides(&side_points_px).unwrap_or(Estimate {
            value: x0,
            std: x0_std,
        });
        Ok(RingAndScale {
            clamp,
            roll_deg,
            elevation_deg,
            camera_distance_m,
            focal_px,
            sin_e,
            scale_per_clamp_row,
            radius_px,
            metres_per_pixel,
            scale_from,
            side_points_px,
            axis_x_px,
        })
    }
}
