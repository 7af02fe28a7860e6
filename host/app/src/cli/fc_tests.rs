//! The JSON contract of `tsukami fc`: field names, order, error objects.

use serde_json::{json, Value};

use super::solve_json;
use crate::cli::fc_problem::Problem;
use crate::cli::fc_solve::ProblemResult;

fn three_finger() -> Value {
    let r = 0.03;
    let contacts: Vec<Value> = (0..3)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 3.0;
            json!({"position": [r * a.cos(), r * a.sin(), 0.0], "normal": [-a.cos(), -a.sin(), 0.0]})
        })
        .collect();
    json!({"contacts": contacts, "mu": 0.5, "f_max": 10.0, "mass": 0.15,
           "center_of_mass": [0.0, 0.0, 0.0], "characteristic_length": 0.03,
           "methods": ["ellipsoid", "exact", "ferrari_canny"]})
}

fn pinch() -> Value {
    json!({"contacts": [{"position": [0.03, 0, 0], "normal": [-1, 0, 0]},
                        {"position": [-0.03, 0, 0], "normal": [1, 0, 0]}],
           "mu": 0.5, "f_max": 10.0, "mass": 0.15, "center_of_mass": [0, 0, 0],
           "gravity": [0, 0, -9.81], "characteristic_length": 0.06})
}

fn solve(v: &Value) -> Value {
    serde_json::from_str(&solve_json(&v.to_string())).expect("the answer is JSON")
}

#[test]
fn single_problem_answers_every_contract_field() {
    let r = solve(&three_finger());
    let e = &r["ellipsoid"];
    assert_eq!(e["force_closure"], true);
    assert_eq!(e["resists_weight"], true);
    assert!(e["margin"].as_f64().unwrap() > 0.0);
    assert!(e["time_ns"].as_u64().is_some());
    let x = &r["exact"];
    assert_eq!(x["force_closure"], true);
    assert_eq!(x["resists_weight"], true);
    let s = x["weight_scale"].as_f64().unwrap();
    assert!((s - 15.0 / (0.15 * 9.81)).abs() < 1e-4 * s, "{s}");
    let forces = x["forces"].as_array().unwrap();
    assert_eq!(forces.len(), 3);
    assert_eq!(forces[0].as_array().unwrap().len(), 3);
    assert!(x["time_ns"].as_u64().is_some());
    let fc = &r["ferrari_canny"];
    assert!(fc["epsilon_l1"].as_f64().unwrap() > 0.0);
    assert!(fc["epsilon_linf"].as_f64().unwrap() >= fc["epsilon_l1"].as_f64().unwrap());
    assert!(fc["time_ns"].as_u64().is_some());
    // The typed result reads the same text back.
    let typed: ProblemResult = serde_json::from_value(r).unwrap();
    assert!(typed.exact.unwrap().force_closure);
}

#[test]
fn arrays_keep_order_and_bad_problems_get_error_objects() {
    let mut bad_normal = three_finger();
    bad_normal["contacts"][1]["normal"] = json!([0.0, 0.0, 0.0]);
    let mut one_contact = pinch();
    one_contact["contacts"].as_array_mut().unwrap().pop();
    let mut mu = pinch();
    mu["mu"] = json!(0.0);
    let mut f_max = pinch();
    f_max["f_max"] = json!(-1.0);
    let mut method = pinch();
    method["methods"] = json!(["ellipsoid", "lmi"]);
    let mut nan = pinch();
    nan["contacts"][0]["position"] = json!([0.03, "NaN", 0.0]);
    let mut long_normal = pinch();
    long_normal["contacts"][0]["normal"] = json!([-2.0, 0.0, 0.0]);
    let mut missing = pinch();
    missing
        .as_object_mut()
        .unwrap()
        .remove("characteristic_length");
    let input = json!([
        pinch(),
        bad_normal,
        one_contact,
        mu,
        f_max,
        method,
        nan,
        three_finger(),
        long_normal,
        missing,
        7
    ]);
    let out = solve(&input);
    let out = out.as_array().unwrap();
    assert_eq!(out.len(), 11);
    let err = |i: usize| &out[i]["error"];
    assert_eq!(out[0]["exact"]["force_closure"], false);
    assert_eq!(out[0]["ellipsoid"]["force_closure"], false);
    assert_eq!(out[0]["exact"]["resists_weight"], true);
    let expect = [
        (1, "invalid_normal", Some("contacts[1].normal")),
        (2, "too_few_contacts", Some("contacts")),
        (3, "not_positive", Some("mu")),
        (4, "not_positive", Some("f_max")),
        (5, "unknown_method", Some("methods[1]")),
        (6, "invalid_type", Some("contacts[0].position[1]")),
        (8, "invalid_normal", Some("contacts[0].normal")),
        (9, "missing_field", Some("characteristic_length")),
        (10, "not_an_object", Some("problem")),
    ];
    for (i, code, field) in expect {
        assert_eq!(err(i)["code"], code, "problem {i}: {}", out[i]);
        assert_eq!(err(i)["index"], i, "problem {i}");
        assert_eq!(err(i)["field"].as_str(), field, "problem {i}");
        assert!(!err(i)["message"].as_str().unwrap().is_empty());
    }
    assert_eq!(out[7]["exact"]["force_closure"], true);
}

#[test]
fn unparseable_document_is_one_error() {
    let out: Value = serde_json::from_str(&solve_json("[{\"contacts\": [")).unwrap();
    assert_eq!(out["error"]["code"], "parse_error");
    assert!(out["error"]["index"].is_null());
    let nan: Value = serde_json::from_str(&solve_json("{\"mu\": NaN}")).unwrap();
    assert_eq!(nan["error"]["code"], "parse_error");
}

#[test]
fn methods_subset_and_options() {
    let mut p = three_finger();
    p["methods"] = json!(["exact"]);
    p["exact_cone"] = json!("polyhedral");
    p["cone_sides"] = json!(6);
    let r = solve(&p);
    assert!(r.get("ellipsoid").is_none() && r.get("ferrari_canny").is_none());
    assert_eq!(r["exact"]["force_closure"], true);

    let mut m = three_finger();
    m["methods"] = json!(["ellipsoid"]);
    m["ellipsoid_scales"] = json!([1.0, 0.5]);
    m["ellipsoid_centre"] = json!("paper");
    m["delta_f"] = json!(0.5);
    let r = solve(&m);
    assert_eq!(r["ellipsoid"]["combinations"], 8);
    assert_eq!(r["ellipsoid"]["force_closure"], true);

    let mut bad = three_finger();
    bad["cone_sides"] = json!(2);
    assert_eq!(solve(&bad)["error"]["field"], "cone_sides");
}

#[test]
fn finger_jacobian_sets_the_contact_force_limit() {
    // Weak fingers: 0.01 N·m over a 0.05 m lever gives 0.2 N per finger,
    // three of them with μ = 0.5 cannot hold 0.15 kg (1.47 N).
    let mut p = three_finger();
    p["methods"] = json!(["exact"]);
    for i in 0..3 {
        let n = p["contacts"][i]["normal"].clone();
        let n: Vec<f64> = serde_json::from_value(n).unwrap();
        // One joint whose lever maps joint speed to motion along the normal.
        p["contacts"][i]["finger"] = json!({
            "jacobian": [[0.05 * n[0]], [0.05 * n[1]], [0.05 * n[2]]],
            "effort_limits": [0.01]
        });
    }
    let r = solve(&p);
    let s = r["exact"]["weight_scale"].as_f64().unwrap();
    assert!((s - 3.0 * 0.5 * 0.2 / (0.15 * 9.81)).abs() < 1e-4, "{s}");
    assert_eq!(r["exact"]["resists_weight"], false);

    let mut bad = three_finger();
    bad["contacts"][0]["finger"] = json!({"jacobian": [[1.0], [0.0]], "effort_limits": [1.0]});
    assert_eq!(solve(&bad)["error"]["field"], "contacts[0].finger.jacobian");
}

#[test]
fn default_methods_are_the_fast_two() {
    let r = solve(&pinch());
    assert!(
        r.get("ellipsoid").is_some() && r.get("exact").is_some(),
        "{r}"
    );
    assert!(r.get("ferrari_canny").is_none(), "{r}");
    let mut twice = pinch();
    twice["methods"] = json!(["exact", "exact", "ferrari_canny"]);
    let r = solve(&twice);
    assert!(
        r.get("ellipsoid").is_none() && r["ferrari_canny"]["epsilon_l1"] == 0.0,
        "{r}"
    );
}

#[test]
fn problem_round_trips_through_serde() {
    let p: Problem = serde_json::from_value(three_finger()).unwrap();
    let again: Problem = serde_json::from_value(serde_json::to_value(&p).unwrap()).unwrap();
    assert_eq!(p, again);
    let err = serde_json::from_value::<Problem>(json!({"contacts": []})).unwrap_err();
    assert!(
        err.to_string().contains("mu") || err.to_string().contains("contacts"),
        "{err}"
    );
}
