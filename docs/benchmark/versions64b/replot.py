"""bench18: a report's plots and markdown again from its report.json (the host run's python3 had
no matplotlib): /usr/bin/python3 docs/benchmark/versions64b/replot.py FOLDER"""
import json, sys
from pathlib import Path
sys.path[:0] = [str(Path(__file__).resolve().parents[3] / d) for d in ("tools", "python_shim")]
import cycles_report
out = Path(sys.argv[1])
data = json.loads((out / "report.json").read_text())
made = cycles_report.plots(out, data)
(out / "report.md").write_text(cycles_report.markdown(data, made))
print(out, len(made), "plots")
