use super::*;

const HEAD: &str = "time,air_temp_c,dew_point_c,wind_m_s,pressure_hpa,cloud_fraction,ghi_w_m2\n";

fn plain(body: &str) -> Result<WeatherFile, WeatherError> {
    parse_plain_csv(&format!("{HEAD}{body}"), "wx.csv", &ReadOptions::default())
}

fn utc(s: &str) -> DateTime<Utc> {
    DateTime::parse_from_rfc3339(s).unwrap().with_timezone(&Utc)
}

fn err(body: &str) -> String {
    plain(body).unwrap_err().to_string()
}

#[test]
fn plain_csv_reads_and_interpolates_linearly() {
    let f = plain(
        "2024-06-21T00:00:00Z,10,5,2,1000,0.5,\n\
         2024-06-21T01:00:00Z,14,7,4,1010,0.7,100\n\
         2024-06-21T02:00:00Z,12,6,3,1005,0.6,200\n",
    )
    .unwrap();
    let h = f.history;
    assert_eq!(h.times.len(), 3);
    // 15 min after 00:00: weight 0.25 (analytic linear interpolation).
    let s = h.at(utc("2024-06-21T00:15:00Z"));
    assert!((s.air_temp_k - (283.15 + 0.25 * 4.0)).abs() < 1e-12);
    assert!((s.pressure_pa - 100_250.0).abs() < 1e-9);
    assert!((s.cloud_fraction.unwrap() - 0.55).abs() < 1e-12);
    assert_eq!(
        s.ghi_w_m2, None,
        "GHI is missing at 00:00, so unknown between"
    );
    let s = h.at(utc("2024-06-21T01:30:00Z"));
    assert!((s.ghi_w_m2.unwrap() - 150.0).abs() < 1e-12);
    assert!((s.wind_speed_m_s - 3.5).abs() < 1e-12);
    // Exactly on a sample with a missing neighbour, the value is kept.
    assert_eq!(h.at(utc("2024-06-21T01:00:00Z")).ghi_w_m2, Some(100.0));
    // Outside the record the end values are held.
    assert_eq!(h.at(utc("2024-06-22T00:00:00Z")), h.samples[2]);
}

#[test]
fn plain_csv_local_time_with_caller_or_file_offset() {
    let body = "2024-06-21T07:00,10,5,2,1000,0\n2024-06-21 08:00:00,11,5,2,1000,0\n";
    let head = "time,air_temp_c,dew_point_c,wind_m_s,pressure_hpa,cloud_fraction\n";
    let e = parse_plain_csv(&format!("{head}{body}"), "wx.csv", &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("wx.csv:2:") && e.contains("no UTC offset"),
        "{e}"
    );
    let opts = ReadOptions {
        utc_offset: FixedOffset::west_opt(5 * 3600),
        ..ReadOptions::default()
    };
    let h = parse_plain_csv(&format!("{head}{body}"), "wx.csv", &opts)
        .unwrap()
        .history;
    assert_eq!(h.times[0], utc("2024-06-21T12:00:00Z"));
    let h = parse_plain_csv(
        &format!("# utc_offset: -05:00\n{head}{body}"),
        "wx.csv",
        &ReadOptions::default(),
    )
    .unwrap()
    .history;
    assert_eq!(h.times[1], utc("2024-06-21T13:00:00Z"));
}

#[test]
fn plain_csv_rh_tenths_and_optional_columns() {
    let text = "time,air_temp_c,rh_percent,wind_m_s,cloud_tenths,sky_temp_c,precip_mm_h,x_note\n\
                2024-01-01T00:00:00Z,20,50,1,3,-10,0.5,hello\n";
    let h = parse_plain_csv(text, "wx.csv", &ReadOptions::default())
        .unwrap()
        .history;
    let s = h.samples[0];
    // Magnus dew point at 20 °C, 50 % (hand-computed: 9.2607 °C).
    assert!(
        (s.dew_point_k - ZERO_C_K - 9.2607).abs() < 1e-3,
        "{}",
        s.dew_point_k
    );
    assert!((s.cloud_fraction.unwrap() - 0.3).abs() < 1e-12);
    assert_eq!(s.pressure_pa, 101_325.0);
    assert!((s.sky_temp_k.unwrap() - 263.15).abs() < 1e-12);
    assert_eq!(s.precip_mm_h, 0.5);
}

/// Dew point from RH against tabulated saturation vapour pressure over
/// water (Smithsonian Meteorological Tables / WMO): e_s(20) = 23.39 hPa,
/// e_s(9.3) = 11.70 → 20 °C 50 % gives 9.3 °C; e_s(30) = 42.47,
/// e_s(26.2) = 34.0 → 30 °C 80 % gives 26.2 °C; e_s(−10) = 2.865,
/// e_s(−16) = 1.766, e_s(−17) = 1.630 → −10 °C 60 % gives −16.35 °C (linear
/// in the table). Tolerance 0.1 K (table rounding and interpolation).
#[test]
fn dew_point_from_rh_vs_tables() {
    for (t, rh, td) in [
        (20.0, 50.0, 9.3),
        (30.0, 80.0, 26.2),
        (0.0, 100.0, 0.0),
        (-10.0, 60.0, -16.35),
    ] {
        let got = dew_point_c_from_rh(t, rh);
        assert!((got - td).abs() < 0.1, "T {t} RH {rh}: {got}");
        assert!((rh_percent_from_dew_point(t, got) - rh).abs() < 1e-9);
    }
}

#[test]
fn errors_name_file_line_and_expectation() {
    let ok = "2024-06-21T00:00:00Z,10,5,2,1000,0.5,\n";
    let e = err(&format!("{ok}2024-06-21T01:00:00Z,10,5,2,1000\n"));
    assert!(e.starts_with("wx.csv:3: 5 fields, expected 7"), "{e}");
    let e = err(&format!("{ok}2024-06-21T01:00:00Z,warm,5,2,1000,0.5,\n"));
    assert!(
        e.starts_with("wx.csv:3: air_temp_c: 'warm' is not a number"),
        "{e}"
    );
    let e = err(&format!("{ok}21/06/2024 01:00,10,5,2,1000,0.5,\n"));
    assert!(
        e.starts_with("wx.csv:3: cannot read time") && e.contains("RFC 3339"),
        "{e}"
    );
    let e = err(&format!("{ok}2024-06-21T01:00:00Z,61,5,2,1000,0.5,\n"));
    assert_eq!(
        e,
        "wx.csv:3: air temperature = 61 is out of range: expected -90 to 60 °C"
    );
    let e = err(&format!("{ok}2024-06-21T01:00:00Z,10,5,-1,1000,0.5,\n"));
    assert!(
        e.starts_with("wx.csv:3: wind speed = -1 is out of range: expected 0 to 100 m/s"),
        "{e}"
    );
    let e = err(&format!("{ok}2024-06-21T01:00:00Z,10,5,1,1000,1.5,\n"));
    assert!(e.contains("cloud fraction = 1.5 is out of range"), "{e}");
    let e = err(&format!("{ok}2024-06-21T01:00:00Z,10,15,1,1000,0.5,\n"));
    assert!(
        e.starts_with("wx.csv:3: dew point 15 °C is above the air temperature 10 °C"),
        "{e}"
    );
    let e = err(&format!("{ok}2024-06-21T01:00:00Z,10,5,1,1000,0.5,-50\n"));
    assert!(e.contains("GHI = -50 is out of range"), "{e}");
    let e = parse_plain_csv(
        "time,air_temp_c,rh_percent,wind_m_s,cloud_fraction\n2024-01-01T00:00:00Z,10,101,1,0\n",
        "wx.csv",
        &ReadOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "wx.csv:2: relative humidity = 101 is out of range: expected 0 to 100 %"
    );
}

#[test]
fn errors_for_order_duplicates_and_gaps() {
    let a = "2024-06-21T03:00:00Z,10,5,2,1000,0.5,\n";
    let e = err(&format!("{a}2024-06-21T02:00:00Z,10,5,2,1000,0.5,\n"));
    assert!(
        e.starts_with(
            "wx.csv:3: time 2024-06-21T02:00Z is earlier than 2024-06-21T03:00Z on line 2"
        ),
        "{e}"
    );
    let e = err(&format!("{a}{a}"));
    assert_eq!(
        e,
        "wx.csv:3: time 2024-06-21T03:00Z repeats line 2: duplicate record"
    );
    let e = err(&format!("{a}2024-06-21T07:00:00Z,10,5,2,1000,0.5,\n"));
    assert!(
        e.starts_with("wx.csv:3: gap of 4.00 h since line 2 (2024-06-21T03:00Z to 2024-06-21T07:00Z); the largest allowed gap is 3.00 h"),
        "{e}"
    );
    let opts = ReadOptions {
        max_gap_s: 6.0 * 3600.0,
        ..ReadOptions::default()
    };
    assert!(
        parse_plain_csv(
            &format!("{HEAD}{a}2024-06-21T07:00:00Z,10,5,2,1000,0.5,\n"),
            "wx.csv",
            &opts
        )
        .is_ok()
    );
}

#[test]
fn header_errors() {
    let e = parse_plain_csv(
        "time,air_temp_c,ghi,wind_m_s\n",
        "wx.csv",
        &ReadOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("wx.csv:1: unknown column 'ghi'") && e.contains("ghi_w_m2"),
        "{e}"
    );
    let e = parse_plain_csv(
        "time,air_temp_c,wind_m_s,cloud_fraction\n",
        "wx.csv",
        &ReadOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "wx.csv:1: the header has no dew_point_c or rh_percent column"
    );
    let e = parse_plain_csv("# only comments\n", "wx.csv", &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("wx.csv: no weather records (expected a header row"),
        "{e}"
    );
}

#[test]
fn tmy3_and_epw_errors() {
    let tmy = "723170,\"GREENSBORO\",NC,-5.0,36.1,-79.95,273\n\
        Date (MM/DD/YYYY),Time (HH:MM),GHI (W/m^2),DNI (W/m^2),DHI (W/m^2),TotCld (tenths),Dry-bulb (C),Dew-point (C),RHum (%),Pressure (mbar),Wspd (m/s)\n\
        06/18/1989,01:00,0,0,0,0,18.3,16.7,90,990,2.6\n\
        06/18/1989,02:00,0,0,0,0,-9900,16.7,90,990,2.6\n";
    let e = parse_tmy3(tmy, "t.csv", &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert_eq!(e, "t.csv:4: Dry-bulb (C) is missing ('-9900')");
    let tmy2 = tmy.replace(
        "06/18/1989,02:00,0,0,0,0,-9900",
        "06/18/1989,25:00,0,0,0,0,18",
    );
    let e = parse_tmy3(&tmy2, "t.csv", &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("t.csv:4: time '25:00': expected HH:MM from 01:00 to 24:00"),
        "{e}"
    );
    // Month boundary of a typical year: July of another year → the error
    // names the scene key and the CLI flag, and no internal API name.
    let tmy3 = tmy.replace(
        "06/18/1989,02:00,0,0,0,0,-9900",
        "07/01/1981,01:00,0,0,0,0,18",
    );
    let e = parse_tmy3(&tmy3, "t.csv", &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "t.csv:4: the records jump from 1989-06-18 (line 3) to 1981-07-01: this is a typical-year \
         file (its months come from different years, 1981 to 1989); set `typical_year = true` in \
         the scene's [weather.file] (irsig therm: --typical-year)"
    );
    let opts = ReadOptions {
        typical_year: Some(YearSpan {
            first: 1989,
            last: 1989,
        }),
        max_gap_s: 400.0 * 3600.0,
        ..ReadOptions::default()
    };
    assert!(parse_tmy3(&tmy3, "t.csv", &opts).is_ok());
    let e = parse_epw("NOT EPW\n", "a.epw", &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("a.epw:1: expected the EPW LOCATION line"),
        "{e}"
    );
}

#[test]
fn check_covers_lists_missing_hours() {
    let mk = |h: &[i64]| {
        let t0 = utc("2024-06-21T00:00:00Z");
        let s = WeatherSample {
            air_temp_k: 290.0,
            dew_point_k: 280.0,
            wind_speed_m_s: 1.0,
            pressure_pa: 101_325.0,
            cloud_fraction: Some(0.0),
            ghi_w_m2: None,
            dni_w_m2: None,
            dhi_w_m2: None,
            sky_temp_k: None,
            precip_mm_h: 0.0,
        };
        WeatherHistory::new(
            h.iter().map(|&x| t0 + Duration::hours(x)).collect(),
            vec![s; h.len()],
            "w",
        )
        .unwrap()
    };
    let h = mk(&[2, 3, 4, 10, 11]);
    assert!(
        h.check_covers(utc("2024-06-21T02:00:00Z"), utc("2024-06-21T04:00:00Z"))
            .is_ok()
    );
    let e = h
        .check_covers(utc("2024-06-21T00:00:00Z"), utc("2024-06-21T12:30:00Z"))
        .unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains(
            "missing 2 h from 2024-06-21T00:00Z to 2024-06-21T02:00Z; 6 h from 2024-06-21T04:00Z to 2024-06-21T10:00Z; \
             2 h from 2024-06-21T11:00Z to 2024-06-21T13:00Z"
        ),
        "{msg}"
    );
    let WeatherError::NotCovered { missing, .. } = e else {
        panic!()
    };
    assert_eq!(missing.len(), 3);
    assert!(WeatherHistory::new(vec![utc("2024-06-21T00:00:00Z"); 2], vec![], "w").is_err());
}

/// The constant-weather cycle: T_min at sunrise, T_max at transit + 2.5 h,
/// the mean half-way (cos π/2 = 0), bounded, and fixed other fields.
/// Sunrise/transit are from the SPA (tested against pvlib elsewhere).
#[test]
fn constant_weather_diurnal_cycle() {
    let p = ConstantWeather {
        wind_m_s: 4.47,
        air_min_c: 12.0,
        air_max_c: 26.0,
        dew_point_c: 8.0,
        cloud_fraction: 0.25,
        pressure_pa: 100_000.0,
        t_max_after_noon_h: 2.5,
    };
    let (lat, lon) = (43.1, -77.6);
    let start = utc("1992-07-14T00:00:00Z");
    let end = utc("1992-07-16T00:00:00Z");
    let h = constant_weather(&p, lat, lon, start, end, 900.0).unwrap();
    assert_eq!(h.times.len(), 2 * 96 + 1);
    assert!(h.check_covers(start, end).is_ok());
    let ev = crate::sun::sun_events_near(utc("1992-07-15T17:00:00Z"), lat, lon);
    let rise = ev.sunrise.unwrap();
    let tx = ev.transit + Duration::minutes(150);
    let at = |t| diurnal_air_temp_c(&p, lat, lon, t);
    assert!((at(rise) - 12.0).abs() < 1e-9);
    assert!((at(tx) - 26.0).abs() < 1e-9);
    assert!((at(rise + (tx - rise) / 2) - 19.0).abs() < 1e-6);
    for s in &h.samples {
        let t = s.air_temp_k - ZERO_C_K;
        assert!((12.0 - 1e-9..=26.0 + 1e-9).contains(&t));
        assert_eq!(s.wind_speed_m_s, 4.47);
        assert!((s.dew_point_k - ZERO_C_K - 8.0).abs() < 1e-12);
        assert_eq!(s.cloud_fraction, Some(0.25));
        assert_eq!(s.ghi_w_m2, None);
    }
    // Rising before the max, falling after (sampled).
    assert!(at(tx - Duration::hours(2)) < at(tx - Duration::hours(1)));
    assert!(at(tx + Duration::hours(2)) < at(tx + Duration::hours(1)));
    // Dew point above the minimum temperature is refused.
    let bad = ConstantWeather {
        dew_point_c: 13.0,
        ..p
    };
    let e = constant_weather(&bad, lat, lon, start, end, 900.0)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("dew point 13 °C is above the minimum air temperature 12 °C"),
        "{e}"
    );
    // Polar night still gives a finite bounded cycle.
    let h = constant_weather(
        &p,
        85.0,
        0.0,
        utc("2021-12-20T00:00:00Z"),
        utc("2021-12-21T00:00:00Z"),
        3600.0,
    )
    .unwrap();
    assert!(h.samples.iter().all(|s| s.air_temp_k.is_finite()));
}

#[test]
fn utc_offset_parsing() {
    assert_eq!(
        parse_utc_offset("-05:00").unwrap(),
        FixedOffset::west_opt(18000).unwrap()
    );
    assert_eq!(parse_utc_offset("+0530").ok(), None);
    assert_eq!(
        parse_utc_offset("+5").unwrap(),
        FixedOffset::east_opt(18000).unwrap()
    );
    assert!(
        parse_utc_offset("EST")
            .unwrap_err()
            .contains("expected e.g. -05:00")
    );
}

/// A typical year without 29 February laid on a leap year repeats its 28
/// February (EnergyPlus's rule), so the record stays hourly; on a common
/// year 28 February 24:00 runs straight into 1 March.
#[test]
fn typical_year_leap_day() {
    let mut tmy = String::from(
        "723170,\"GREENSBORO\",NC,-5.0,36.1,-79.95,273\n\
         Date (MM/DD/YYYY),Time (HH:MM),GHI (W/m^2),DNI (W/m^2),DHI (W/m^2),TotCld (tenths),Dry-bulb (C),Dew-point (C),RHum (%),Pressure (mbar),Wspd (m/s)\n",
    );
    for (date, t0) in [("02/28/1985", 0.0), ("03/01/1979", 100.0)] {
        for h in 1..=24 {
            let t = (t0 + h as f64) / 10.0;
            tmy += &format!("{date},{h:02}:00,0,0,0,5,{t},-20,50,1000,2\n");
        }
    }
    let read = |y: i32| {
        let opts = ReadOptions {
            typical_year: Some(YearSpan { first: y, last: y }),
            ..ReadOptions::default()
        };
        parse_tmy3(&tmy, "t.csv", &opts).unwrap().history
    };
    // 1992: 28 Feb (24 h) + 29 Feb (copy, 24 h) + 1 Mar (24 h), hourly.
    let h = read(1992);
    let stamps: Vec<_> = h
        .times
        .iter()
        .filter(|t| t.timestamp() % 3600 == 0)
        .collect();
    assert_eq!(stamps.len(), 72);
    assert!(
        h.check_covers(utc("1992-02-28T06:00:00Z"), utc("1992-03-02T05:00:00Z"))
            .is_ok()
    );
    // 29 Feb 12:00 local (17:00 UTC) holds 28 Feb 12:00's air temperature, 1.2 °C.
    let s = h.at(utc("1992-02-29T17:00:00Z"));
    assert!(
        (s.air_temp_k - ZERO_C_K - 1.2).abs() < 1e-12,
        "{}",
        s.air_temp_k
    );
    // 1991: 48 hourly stamps, 28 Feb 24:00 (1 Mar 05:00 UTC) then 1 Mar 01:00 (06:00 UTC).
    let h = read(1991);
    assert_eq!(
        h.times.iter().filter(|t| t.timestamp() % 3600 == 0).count(),
        48
    );
    assert!(
        h.check_covers(utc("1991-02-28T06:00:00Z"), utc("1991-03-02T05:00:00Z"))
            .is_ok()
    );
    let s = h.at(utc("1991-03-01T06:00:00Z"));
    assert!((s.air_temp_k - ZERO_C_K - 10.1).abs() < 1e-12);
}

/// 72 hourly records from 2024-06-20T00Z of a clear sky measured at
/// 40° N 80° W (GHI = 1000 W/m² · sin(sun elevation) there), as a station
/// file `station.csv` would give them; returns the first time and the record.
fn clear_record_at_80w() -> (DateTime<Utc>, WeatherHistory) {
    let t0 = utc("2024-06-20T00:00:00Z");
    let times: Vec<_> = (0..72).map(|h| t0 + Duration::hours(h)).collect();
    let samples = times
        .iter()
        .map(|t| {
            let e = crate::sun::solar_position(*t, 40.0, -80.0, 0.0).true_elevation_deg;
            WeatherSample {
                air_temp_k: 295.0,
                dew_point_k: 285.0,
                wind_speed_m_s: 2.0,
                pressure_pa: 101_325.0,
                cloud_fraction: None,
                ghi_w_m2: Some((1000.0 * e.to_radians().sin()).max(0.0)),
                dni_w_m2: None,
                dhi_w_m2: None,
                sky_temp_k: None,
                precip_mm_h: 0.0,
            }
        })
        .collect();
    let h = WeatherHistory {
        times,
        samples,
        source: "station.csv".into(),
    };
    (t0, h)
}

/// A clear-sky-shaped record (GHI = 1000·sin(elevation)) of a station at
/// 80° W applied to a site at the same longitude: no warning; at 35° W (3 h
/// of solar time east): the station's afternoon sunlight falls after the
/// site's sunset, and the warning names those hours; at 125° W: the
/// site's sun is up while the record is dark.
#[test]
fn stand_in_sunlight_in_another_solar_time_is_named() {
    let (t0, h) = clear_record_at_80w();
    let (from, to) = (t0, t0 + Duration::hours(71));
    assert_eq!(sunlight_mismatch(&h, 40.0, -80.0, from, to), None);
    let east = sunlight_mismatch(&h, 40.0, -35.0, from, to).expect("east: warned");
    assert!(east.contains("while the site's sun is down at"), "{east}");
    // Station sunset ~00:55Z (19:35 solar time): at 00:00Z its sun is
    // ~10° up (GHI ~170 W/m²) while the 3-h-east site's sun set at ~21:55Z.
    assert!(east.contains("2024-06-21T00:00Z"), "{east}");
    assert!(east.contains("station.csv"), "{east}");
    let west = sunlight_mismatch(&h, 40.0, -125.0, from, to).expect("west: warned");
    assert!(
        west.contains("no measured sunlight while the site's sun is above"),
        "{west}"
    );
}

/// Issue #30 item 6: a stand-in record measured 45° west of the site,
/// moved by `stand_in_solar_shift` (−3 h), meets the site's sun: the
/// sunlight check that named its hours before the shift finds none after
/// it (same latitude); a site 2.34° east (the airfield's Rochester for
/// Greensboro) moves it 9 min 22 s earlier, a site west later; a file
/// without a station cannot be moved and the message says why.
#[test]
fn stand_in_record_is_moved_to_the_site_solar_time() {
    let (t0, h) = clear_record_at_80w();
    let station = WeatherStation {
        name: "station".into(),
        lat_deg: 40.0,
        lon_deg: -80.0,
        elevation_m: 0.0,
        utc_offset_h: -5.0,
    };
    let (from, to) = (t0 + Duration::hours(4), t0 + Duration::hours(66));
    assert!(sunlight_mismatch(&h, 40.0, -35.0, from, to).is_some());
    let by = stand_in_solar_shift(Some(&station), "station.csv", -35.0).unwrap();
    assert_eq!(by, Duration::hours(-3));
    let moved = h.clone().shifted(by);
    assert_eq!(moved.times[5], h.times[5] - Duration::hours(3));
    assert_eq!(sunlight_mismatch(&moved, 40.0, -35.0, from, to), None);
    // West of the station: later. Across the date line: the short way.
    assert_eq!(
        stand_in_solar_shift(Some(&station), "s", -125.0).unwrap(),
        Duration::hours(3)
    );
    let far_east = WeatherStation {
        lon_deg: 179.0,
        ..station.clone()
    };
    assert_eq!(
        stand_in_solar_shift(Some(&far_east), "s", -179.0).unwrap(),
        Duration::minutes(-8)
    );
    // The airfield: Greensboro (79.950 W) for Rochester (77.6088 W).
    let gso = WeatherStation {
        lon_deg: -79.95,
        ..station
    };
    assert_eq!(
        stand_in_solar_shift(Some(&gso), "s", -77.6088).unwrap(),
        Duration::seconds(-562)
    );
    let why = stand_in_solar_shift(None, "wx.csv", -77.6).unwrap_err();
    assert!(
        why.contains("wx.csv") && why.contains("cannot be moved to the site's solar time"),
        "{why}"
    );
}
