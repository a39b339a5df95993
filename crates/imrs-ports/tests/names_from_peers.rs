//! A port without a user list, claimed by peers under ever new names: the process keeps at
//! most `Name::MOST_FROM_PEERS` names made from their text, and refuses the next claim by
//! name. Its own test binary, since the bound is the process's.

use imrs_ports::{AnyUser, ClaimRefused, Name, Port, PortSpec, usage};

#[test]
fn claims_under_new_names_are_refused_by_name_once_the_bound_is_kept() {
    let open: Port<u64, u64, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("OPEN_GATE", "GATEKEEPER"));
    let listed: Port<u64, u64, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("LISTED_GATE", "GATEKEEPER").user_list(["ROBOT"]));
    let local = Name::from("LOCAL_MODULE");
    // Eight peers at once, each claiming new names, more than the bound in all.
    const PEERS: usize = 8;
    let per_peer = Name::MOST_FROM_PEERS / PEERS + 100;
    let outcomes: Vec<(String, Result<Name, ClaimRefused>)> = std::thread::scope(|scope| {
        let peers: Vec<_> = (0..PEERS)
            .map(|peer| {
                let open = &open;
                scope.spawn(move || {
                    (0..per_peer)
                        .map(|i| {
                            let module = format!("CHURN_{peer}_{i}");
                            // Names known already never count: a local one, claimed between.
                            assert_eq!(open.claim("LOCAL_MODULE"), Ok(Name::from("LOCAL_MODULE")));
                            let claimed = open.claim(&module);
                            (module, claimed)
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        peers
            .into_iter()
            .flat_map(|peer| peer.join().unwrap())
            .collect()
    });
    let accepted = outcomes
        .iter()
        .filter(|(_, claimed)| claimed.is_ok())
        .count();
    assert_eq!(accepted, Name::MOST_FROM_PEERS);
    for (module, claimed) in &outcomes {
        match claimed {
            Ok(name) => assert_eq!(name.as_str(), module),
            Err(refused) => {
                assert_eq!(
                    refused,
                    &ClaimRefused::TooManyNames {
                        port: "OPEN_GATE".into(),
                        module: module.clone()
                    }
                );
                assert_eq!(
                    refused.to_string(),
                    format!(
                        "module {module} cannot use port OPEN_GATE: this process already keeps \
                         {} module names its peers made; give port OPEN_GATE a user list",
                        Name::MOST_FROM_PEERS
                    )
                );
                assert_eq!(Name::known(module), None, "{module} was kept");
            }
        }
    }
    // What was accepted stays accepted; a listed module and a local one are never refused.
    let (first, _) = outcomes
        .iter()
        .find(|(_, claimed)| claimed.is_ok())
        .unwrap();
    assert!(open.claim(first).is_ok());
    assert_eq!(open.claim("LOCAL_MODULE"), Ok(local));
    assert_eq!(listed.claim("ROBOT"), Ok(Name::from("ROBOT")));
    // An accepted claim attaches; the port still serves.
    let _robot = open.user_named(first.as_str()).unwrap();
}
