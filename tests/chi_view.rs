//! `kapaint chi --view`: the specular part of k_a at one view angle, as the issue spells it
//! (`n,view,chi`, `n,view,chi1,chi0` for Cook-Torrance, one row per pair, 17 significant
//! digits), and its bad input (exit 2, one line, no table).
#![expect(
    clippy::expect_used,
    reason = "test helpers: a failed expectation is a failed test"
)]

use std::process::Output;

fn kapaint(args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_kapaint"))
        .args(args)
        .output()
        .expect("kapaint runs")
}

fn stdout(o: &Output) -> String {
    assert!(o.status.success(), "{o:?}");
    String::from_utf8(o.stdout.clone()).expect("utf-8")
}

#[test]
fn chi_view_prints_one_row_per_pair() {
    let out = stdout(&kapaint(&[
        "chi", "--model", "phong", "--method", "exact", "--view", "0", "--view", "60", "100", "10",
    ]));
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "n,view,chi");
    let rows: Vec<Vec<&str>> = lines[1..].iter().map(|l| l.split(',').collect()).collect();
    let pairs: Vec<(&str, &str)> = rows.iter().map(|r| (r[0], r[1])).collect();
    assert_eq!(
        pairs,
        [("100", "0"), ("100", "60"), ("10", "0"), ("10", "60")]
    );
    let value = |r: &Vec<&str>| r[2].parse::<f64>().expect("number");
    // The numbers: head-on 0.0796 at n = 100, 0.0073 at 60 degrees; n = 10 head-on is
    // 63/256; 17 significant digits.
    assert!((value(&rows[0]) - 0.0796).abs() < 5e-5);
    assert!((value(&rows[1]) - 0.0073).abs() < 5e-5);
    assert!((value(&rows[2]) - 63.0 / 256.0).abs() < 1e-15);
    assert!(
        rows.iter()
            .all(|r| r[2].split('e').next().expect("mantissa").len() == 18)
    );
    // Cook-Torrance prints both parts; without --view the output is as before.
    let ct = stdout(&kapaint(&[
        "chi",
        "--model",
        "cook-torrance",
        "--method",
        "fast",
        "--view",
        "30",
        "64",
    ]));
    assert!(ct.starts_with("n,view,chi1,chi0\n64,30,"), "{ct}");
    let plain = stdout(&kapaint(&[
        "chi", "--model", "blinn", "--method", "exact", "100",
    ]));
    assert!(plain.starts_with("n,chi\n100,"), "{plain}");
}

#[test]
fn bad_views_exit_2_with_one_line() {
    let many: Vec<String> = (0..4097).map(|_| "--view=1".to_string()).collect();
    let mut too_many = vec!["chi", "--model", "phong", "--method", "exact"];
    too_many.extend(many.iter().map(String::as_str));
    too_many.push("10");
    for args in [
        vec![
            "chi", "--model", "phong", "--method", "exact", "--view", "90", "10",
        ],
        vec![
            "chi", "--model", "phong", "--method", "exact", "--view", "-1", "10",
        ],
        vec![
            "chi", "--model", "phong", "--method", "exact", "--view", "nan", "10",
        ],
        vec![
            "chi", "--model", "phong", "--method", "paper", "--view", "10", "10",
        ],
        vec![
            "chi", "--model", "phong", "--method", "fast", "--view", "10", "20000",
        ],
        too_many,
    ] {
        let o = kapaint(&args);
        assert_eq!(o.status.code(), Some(2), "{:?}", &args[..args.len().min(8)]);
        assert!(o.stdout.is_empty());
        assert_eq!(String::from_utf8_lossy(&o.stderr).lines().count(), 1);
    }
}
