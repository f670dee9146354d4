"""Draw every catalogue case's diagram (counted by the flow) into docs/images/case_<name>.png."""
import json, sys, time
from chargedesign.model.catalogue import catalogue_cases
from chargedesign.topology.case_map import diagram_refusal
from chargedesign.topology.case_diagram import case_diagram
rows = []
for case in catalogue_cases():
    refusal = diagram_refusal(case)
    if refusal:
        rows.append({"case": case.name, "refused": refusal}); print(case.name, "refused", flush=True); continue
    t = time.perf_counter()
    try:
        d = case_diagram(case, case.level or 0)
    except Exception as exc:  # the gallery records what happened
        rows.append({"case": case.name, "error": f"{type(exc).__name__}: {exc}"}); print(case.name, "error", exc, flush=True); continue
    seconds = time.perf_counter() - t
    name = case.name.replace("-", "_")
    d.plot().savefig(f"docs/images/case_{name}.png", dpi=90)
    s = d._summary()
    rows.append({"case": case.name, "level": str(case.level or 0), "seconds": round(seconds, 1), **s,
                 "names": sorted(set(d.raw.names))})
    print(case.name, s, round(seconds, 1), flush=True)
json.dump(rows, open("/tmp/casediag/gallery.json", "w"), indent=1)
