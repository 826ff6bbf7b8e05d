"""Reports, tables and drawings of every api/ example, checked with real tools (run by .ci/formats).

* CSV (`Accept: text/csv`, every table the OpenAPI document names): read back with Python's csv
  module; every numeric cell is compared with the JSON answer of the same request: the answer is
  parsed keeping each number's text (`parse_float=str`), a column whose name is an array of the
  answer as long as the table is compared element by element as floats, and every other numeric
  cell must be one of the answer's numbers.
* Report (`Accept: text/html`): parsed with html.parser; no element loads anything (no src, href,
  link, img, iframe, object, embed, url() or @import); exactly two scripts, both
  `application/json`; `#request` is the exact request bytes and their SHA-256 is shown; `#answer`
  is the JSON answer (timings aside).
* DXF (`Accept: image/vnd.dxf`): read with ezdxf and audited: no error; `$INSUNITS` as the
  endpoint's unit; at least one entity per layer drawn.
* One report (the cognates example) rendered in headless chromium: no network request, the
  embedded JSON parses in the browser, the inline SVG has a size; screenshot and PDF saved.

Usage: python tests/browser/formats_check.py BASE_URL ARTIFACT_DIR
"""

import base64
import csv
import hashlib
import html.parser
import io
import json
import math
import os
import re
import sys
import tempfile
import urllib.error
import urllib.request

import ezdxf

BASE, ARTIFACTS = sys.argv[1], sys.argv[2]
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
os.makedirs(ARTIFACTS, exist_ok=True)
FAILURES = []
TIMING = re.compile(r"(elapsed_ms|compute_ms|compute_us|timing_ms|cpu_ms|wall_ms|threads)")
UNITS = {"/v1/irefc-stress": 4, "/v1/irefc-efficiency": 4, "/v1/cognates": 0,
         "/v1/continuum-workspace": 6, "/v1/spatial-coupling": 6}


def fail(msg):
    FAILURES.append(msg)
    print("FAIL:", msg)


def post(path, accept, body):
    req = urllib.request.Request(BASE + path, data=body, method="POST",
                                 headers={"content-type": "application/json", "accept": accept})
    try:
        with urllib.request.urlopen(req, timeout=300) as r:
            return r.status, r.headers.get("content-type", ""), r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.headers.get("content-type", ""), e.read()


def tables_of(doc, path):
    content = doc["paths"][path]["post"]["responses"]["200"]["content"]
    desc = content.get("text/csv", {}).get("schema", {}).get("description", "")
    return re.findall(r"`([a-z_0-9]+)`: ", desc)


def number_texts(v, out):
    if isinstance(v, str) and re.fullmatch(r"-?\d+(\.\d+)?([eE][-+]?\d+)?", v):
        out.add(v)
    elif isinstance(v, list):
        for x in v:
            number_texts(x, out)
    elif isinstance(v, dict):
        for x in v.values():
            number_texts(x, out)


def arrays_named(v, name, n, out):
    if isinstance(v, dict):
        for k, x in v.items():
            if k == name and isinstance(x, list) and len(x) == n and all(not isinstance(e, (list, dict)) for e in x):
                out.append(x)
            arrays_named(x, name, n, out)
    elif isinstance(v, list):
        for x in v:
            arrays_named(x, name, n, out)


def is_num(s):
    try:
        return math.isfinite(float(s))
    except ValueError:
        return False


def check_csv(label, path, body, answer_text):
    answer = json.loads(answer_text, parse_float=str, parse_int=str)
    numbers = set()
    number_texts(answer, numbers)
    doc_tables = tables_of(DOC, path)
    compared = 0
    for table in [None] + doc_tables:
        query = "" if table is None else "?table=" + table
        status, ctype, data = post(path + query, "text/csv", body)
        if status == 406:
            problem = json.loads(data)
            if problem.get("code") != "NOTHING_TO_TABULATE":
                fail(f"{label}{query}: 406 {problem}")
            continue
        if status != 200 or not ctype.startswith("text/csv"):
            fail(f"{label}{query}: {status} {ctype}")
            continue
        rows = list(csv.reader(io.StringIO(data.decode("utf-8"))))
        header, rows = rows[0], rows[1:]
        if not rows:
            fail(f"{label}{query}: no rows")
        for i, h in enumerate(header):
            name = h.split(" [")[0]
            col = [r[i] for r in rows]
            found = []
            arrays_named(answer, name, len(rows), found)

            def same(ref):
                return all(is_num(c) == (isinstance(j, str) and is_num(j)) and (not is_num(c) or float(c) == float(j))
                           for c, j in zip(col, ref))

            if not TIMING.search(name) and any(same(ref) for ref in found):
                # The column is an array of the answer, element by element.
                compared += len(col)
                continue
            # Otherwise (a column of records), every numeric cell is one of the answer's numbers.
            for k, c in enumerate(col):
                if is_num(c) and not TIMING.search(name) and name not in ("segment", "component", "row", "wave", "i", "j") \
                        and c not in numbers:
                    fail(f"{label}{query}: column {h} row {k}: {c} is not a number of the JSON answer")
                    break
                compared += 1
        with open(os.path.join(ARTIFACTS, f"{label}{'.' + table if table else ''}.csv"), "wb") as f:
            f.write(data)
    return compared


class Page(html.parser.HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.scripts, self.current, self.bad, self.style, self.in_style = [], None, [], "", False
        self.svgs = 0

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag in ("link", "img", "iframe", "object", "embed", "audio", "video", "source", "base"):
            self.bad.append(tag)
        for k in ("src", "href", "srcset", "xlink:href", "action", "data"):
            if k in a and tag not in ("svg",):
                self.bad.append(f"{tag}[{k}={a[k]}]")
        if tag == "script":
            self.current = [a.get("type"), a.get("id"), ""]
        if tag == "style":
            self.in_style = True
        if tag == "svg":
            self.svgs += 1

    def handle_endtag(self, tag):
        if tag == "script" and self.current is not None:
            self.scripts.append(tuple(self.current))
            self.current = None
        if tag == "style":
            self.in_style = False

    def handle_data(self, data):
        if self.current is not None:
            self.current[2] += data
        if self.in_style:
            self.style += data


def strip_timing(v):
    if isinstance(v, dict):
        return {k: strip_timing(x) for k, x in v.items() if not TIMING.search(k)}
    if isinstance(v, list):
        return [strip_timing(x) for x in v]
    return v


def check_report(label, path, body, answer_text):
    status, ctype, data = post(path, "text/html", body)
    if status != 200 or not ctype.startswith("text/html"):
        fail(f"{label}: report {status} {ctype}")
        return None
    text = data.decode("utf-8")
    p = Page()
    p.feed(text)
    p.close()
    if p.bad:
        fail(f"{label}: report loads from elsewhere: {p.bad[:5]}")
    if "url(" in p.style or "@import" in p.style:
        fail(f"{label}: the style loads from elsewhere")
    if [(t, i) for t, i, _ in p.scripts] != [("application/json", "request"), ("application/json", "answer")]:
        fail(f"{label}: scripts {[(t, i) for t, i, _ in p.scripts]}")
        return None
    request = p.scripts[0][2].replace("\\u003c", "<").encode("utf-8")
    if request != body:
        fail(f"{label}: the embedded request is not the exact request")
    if hashlib.sha256(body).hexdigest() not in text:
        fail(f"{label}: the request's SHA-256 is not in the report")
    if strip_timing(json.loads(p.scripts[1][2])) != strip_timing(json.loads(answer_text)):
        fail(f"{label}: the embedded answer is not the JSON answer")
    for section in ("Provenance", "Inputs", "Results", "Method and references", "Warnings", "Solver report"):
        if f">{section}</h2>" not in text:
            fail(f"{label}: no section {section}")
    out = os.path.join(ARTIFACTS, f"{label}.html")
    with open(out, "wb") as f:
        f.write(data)
    return out


def check_dxf(label, path, body):
    status, ctype, data = post(path, "image/vnd.dxf", body)
    if status == 406:
        print(f"  {label}: no drawing ({json.loads(data).get('code')})")
        return False
    if status != 200 or ctype != "image/vnd.dxf":
        fail(f"{label}: DXF {status} {ctype}")
        return False
    out = os.path.join(ARTIFACTS, f"{label}.dxf")
    with open(out, "wb") as f:
        f.write(data)
    doc = ezdxf.readfile(out)
    auditor = doc.audit()
    if auditor.has_errors:
        fail(f"{label}: ezdxf audit errors: {[e.message for e in auditor.errors[:5]]}")
    units = doc.header.get("$INSUNITS")
    if units != UNITS[path]:
        fail(f"{label}: $INSUNITS {units}, want {UNITS[path]}")
    layers = {}
    for e in doc.modelspace():
        layers[e.dxf.layer] = layers.get(e.dxf.layer, 0) + 1
    if not layers:
        fail(f"{label}: empty drawing")
    print(f"  {label}: DXF {doc.dxfversion}, $INSUNITS {units}, audit: {len(auditor.errors)} errors, "
          f"{len(auditor.fixes)} fixes; layers {layers}")
    return True


def render_in_browser(report):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = "/usr/bin/chromium"
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                 "--no-first-run", "--disable-background-networking", "--disable-component-update",
                 "--disable-sync", "--window-size=1200,1600", f"--user-data-dir={tempfile.mkdtemp()}"):
        opts.add_argument(flag)
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
    try:
        driver.get("file://" + os.path.abspath(report))
        resources = driver.execute_script("return performance.getEntriesByType('resource').map(e => e.name)")
        if resources:
            fail(f"browser: the report requested {resources[:5]}")
        ok = driver.execute_script(
            "const q = JSON.parse(document.getElementById('request').textContent);"
            "const a = JSON.parse(document.getElementById('answer').textContent);"
            "return typeof q === 'object' && typeof a === 'object';")
        if not ok:
            fail("browser: the embedded JSON does not parse")
        size = driver.execute_script(
            "const s = document.querySelector('figure svg'); if (!s) return [0, 0];"
            "const r = s.getBoundingClientRect(); return [r.width, r.height];")
        if not (size[0] > 100 and size[1] > 100):
            fail(f"browser: the inline picture has size {size}")
        driver.save_screenshot(os.path.join(ARTIFACTS, "report.png"))
        pdf = driver.print_page()
        with open(os.path.join(ARTIFACTS, "report.pdf"), "wb") as f:
            f.write(base64.b64decode(pdf))
        print(f"  browser: rendered {report}; picture {size[0]:.0f}×{size[1]:.0f} px; "
              f"{len(resources)} network requests; report.png and report.pdf saved")
    finally:
        driver.quit()


with urllib.request.urlopen(BASE + "/openapi.json", timeout=60) as r:
    DOC = json.load(r)
with open(os.path.join(ROOT, "api", "examples.json")) as f:
    EXAMPLES = json.load(f)["examples"]

n_csv = n_reports = n_dxf = 0
browser_report = None
for ex in EXAMPLES:
    path, file = ex["endpoint"], ex["file"]
    label = file.replace("/", "_").removesuffix(".json")
    with open(os.path.join(ROOT, "api", file), "rb") as f:
        body = f.read()
    status, _, answer = post(path, "application/json", body)
    if status != 200:
        fail(f"{label}: JSON {status}")
        continue
    n_csv += check_csv(label, path, body, answer)
    report = check_report(label, path, body, answer)
    n_reports += report is not None
    if file == "cognates/table1.json":
        browser_report = report
    if path in UNITS:
        n_dxf += check_dxf(label, path, body)
    print(f"{label}: checked")

if browser_report:
    render_in_browser(browser_report)
else:
    fail("no report to render in the browser")

print(f"{n_csv} CSV cells compared with the JSON answers, {n_reports} reports, {n_dxf} drawings audited")
if n_reports != len(EXAMPLES) or n_dxf < 6 or n_csv == 0:
    fail("fewer checks than examples")
if FAILURES:
    print(f"FAILED: {len(FAILURES)} format checks failed", file=sys.stderr)
    sys.exit(1)
print("formats: all checks passed")
