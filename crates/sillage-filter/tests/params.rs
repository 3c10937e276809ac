//! Parameters: the paper's defaults are valid, every invalid value is refused with a message
//! naming its key, and the serde form is strict.

use sillage_filter::{
    BedloadModel, BedloadParams, FilterParams, FilterSpec, KinematicParams, Noise2, ResampleScheme,
    Resampling, Switching, SwitchingParams, TRANSITION_EQ11,
};

fn bedload_error(params: BedloadParams) -> String {
    BedloadModel::new(params)
        .expect_err("invalid parameters must be refused")
        .to_string()
}

#[test]
fn defaults_and_eq11_are_valid() {
    BedloadModel::new(BedloadParams::default()).unwrap();
    BedloadModel::new(BedloadParams {
        transition: TRANSITION_EQ11,
        unknown_transition: [0.33, 0.33, 0.34],
        ..Default::default()
    })
    .unwrap();
    FilterSpec::new(&FilterParams::default(), 0).unwrap();
    let defaults = FilterParams::default();
    assert_eq!(defaults.particles, 100);
    assert_eq!(defaults.resampling.scheme, ResampleScheme::Multinomial);
    assert_eq!(defaults.resampling.ess_fraction, None);
}

#[test]
fn bedload_errors_name_the_key() {
    let cases: Vec<(&str, BedloadParams)> = vec![
        (
            "`transition`",
            BedloadParams {
                transition: [[0.80, 0.15, 0.05], [0.10, 0.80, 0.05], [0.05, 0.15, 0.80]],
                ..Default::default()
            },
        ),
        (
            "`transition`",
            BedloadParams {
                transition: [[1.05, -0.05, 0.0], [0.1, 0.8, 0.1], [0.05, 0.15, 0.8]],
                ..Default::default()
            },
        ),
        (
            "`unknown_transition`",
            BedloadParams {
                unknown_transition: [0.3, 0.3, 0.3],
                ..Default::default()
            },
        ),
        (
            "`roll_vel_noise.var_x`",
            BedloadParams {
                roll_vel_noise: Noise2::diagonal(-1.0, 1.0),
                ..Default::default()
            },
        ),
        (
            "`rest_pos_noise.var_y`",
            BedloadParams {
                rest_pos_noise: Noise2::diagonal(0.25, f64::NAN),
                ..Default::default()
            },
        ),
        (
            "`salt_pos_noise.cov_xy`",
            BedloadParams {
                salt_pos_noise: Noise2 {
                    var_x: 1.0,
                    var_y: 1.0,
                    cov_xy: -1.5,
                },
                ..Default::default()
            },
        ),
        (
            "`rebound_probability`",
            BedloadParams {
                rebound_probability: 1.5,
                ..Default::default()
            },
        ),
        (
            "`young_variance_factor`",
            BedloadParams {
                young_variance_factor: 0.0,
                ..Default::default()
            },
        ),
    ];
    for (key, params) in cases {
        let message = bedload_error(params);
        assert!(message.contains(key), "expected {key} in: {message}");
    }
    let message = bedload_error(BedloadParams {
        transition: [[0.80, 0.15, 0.05], [0.10, 0.80, 0.05], [0.05, 0.15, 0.80]],
        ..Default::default()
    });
    assert!(message.contains("row 1 sums to 0.95"), "{message}");
}

#[test]
fn filter_and_switching_errors_name_the_key() {
    let zero = FilterParams {
        particles: 0,
        ..Default::default()
    };
    let message = FilterSpec::new(&zero, 1).unwrap_err().to_string();
    assert!(message.contains("`particles` = 0"), "{message}");
    let ess = FilterParams {
        resampling: Resampling {
            ess_fraction: Some(0.0),
            ..Default::default()
        },
        ..Default::default()
    };
    let message = FilterSpec::new(&ess, 1).unwrap_err().to_string();
    assert!(message.contains("`resampling.ess_fraction`"), "{message}");

    let noise = Noise2::diagonal(1.0, 1.0);
    let models = vec![
        KinematicParams::ConstantPosition { pos_noise: noise },
        KinematicParams::ConstantVelocity {
            pos_noise: noise,
            vel_noise: Noise2::diagonal(1.0, -2.0),
        },
    ];
    let message = Switching::new(&SwitchingParams {
        models: models.clone(),
        transition: vec![vec![0.5, 0.5], vec![0.5, 0.5]],
    })
    .unwrap_err()
    .to_string();
    assert!(message.contains("`models[1].vel_noise.var_y`"), "{message}");
    let message = Switching::new(&SwitchingParams {
        models: models[..1].to_vec(),
        transition: vec![vec![0.5, 0.5]],
    })
    .unwrap_err()
    .to_string();
    assert!(
        message.contains("`transition`") && message.contains("1×1"),
        "{message}"
    );
    let message = Switching::new(&SwitchingParams {
        models: vec![],
        transition: vec![],
    })
    .unwrap_err()
    .to_string();
    assert!(message.contains("`models`"), "{message}");
}

#[test]
fn serde_round_trip_is_strict() {
    let params = BedloadParams::default();
    let json = serde_json::to_string(&params).unwrap();
    let back: BedloadParams = serde_json::from_str(&json).unwrap();
    assert_eq!(back, params);
    // Missing keys take the defaults; unknown keys are refused.
    let partial: BedloadParams = serde_json::from_str(r#"{"rebound_probability": 0.25}"#).unwrap();
    assert_eq!(partial.transition, params.transition);
    assert_eq!(partial.rebound_probability, 0.25);
    assert!(serde_json::from_str::<BedloadParams>(r#"{"rebound_probabilty": 0.25}"#).is_err());
    let filter: FilterParams = serde_json::from_str(
        r#"{"particles": 500, "resampling": {"scheme": "systematic", "ess_fraction": 0.5}}"#,
    )
    .unwrap();
    assert_eq!(filter.particles, 500);
    assert_eq!(filter.resampling.scheme, ResampleScheme::Systematic);
    let model: KinematicParams = serde_json::from_str(
        r#"{"model": "constant_velocity", "pos_noise": {"var_x": 1, "var_y": 1}, "vel_noise": {"var_x": 0.5, "var_y": 0.5, "cov_xy": 0.1}}"#,
    )
    .unwrap();
    assert!(matches!(model, KinematicParams::ConstantVelocity { .. }));
}
