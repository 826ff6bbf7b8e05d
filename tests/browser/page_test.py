"""The page at `/` in a real headless browser (Debian's chromium + chromedriver, via Selenium).

Opens the page served by the binary, runs two api/ examples through it, and asserts that the JSON
answer and an SVG picture with data appear; saves a screenshot per example as a test artifact.

Usage: python tests/browser/page_test.py BASE_URL ARTIFACT_DIR
"""

import os
import sys
import tempfile
import time

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support import expected_conditions as ec
from selenium.webdriver.support.ui import WebDriverWait

BASE, ARTIFACTS = sys.argv[1], sys.argv[2]
EXAMPLES = [("/v1/cam-law/evaluate", "cam_law/evaluate_table1.json"), ("/v1/cognates", "cognates/table1.json")]

os.makedirs(ARTIFACTS, exist_ok=True)
opts = webdriver.ChromeOptions()
opts.binary_location = "/usr/bin/chromium"
for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--disable-quic",
             "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync",
             "--window-size=1400,1000", f"--user-data-dir={tempfile.mkdtemp()}"):
    opts.add_argument(flag)
driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
wait = WebDriverWait(driver, 30)
try:
    driver.get(BASE + "/")
    wait.until(ec.presence_of_element_located((By.CSS_SELECTOR, "nav button")))
    for endpoint, file in EXAMPLES:
        button = driver.find_element(By.CSS_SELECTOR, f'nav button[data-file="{file}"]')
        button.click()
        assert endpoint in driver.find_element(By.ID, "endpoint").text, "the example did not select its endpoint"
        request = driver.find_element(By.ID, "request").get_attribute("value")
        assert '"' in request and len(request) > 20, "the example was not loaded into the editor"
        driver.find_element(By.ID, "send").click()
        wait.until(lambda d: "200" in d.find_element(By.ID, "status").text)
        answer = driver.find_element(By.ID, "answer").text
        assert answer.strip().startswith("{"), f"{file}: no JSON answer shown"
        img = wait.until(ec.presence_of_element_located((By.CSS_SELECTOR, "#figure img")))
        wait.until(lambda d: d.execute_script("return arguments[0].complete && arguments[0].naturalWidth > 0", img))
        svg = driver.execute_script(
            "const r = await fetch(arguments[0], {method: 'POST', headers: {'content-type': 'application/json',"
            " accept: 'image/svg+xml'}, body: arguments[1]}); return await r.text();", endpoint, request)
        assert svg.lstrip().startswith("<svg") or "<svg" in svg[:300], f"{file}: the picture is not SVG"
        assert ("<path" in svg or "<polyline" in svg or "<rect" in svg), f"{file}: the SVG has no data series"
        shot = os.path.join(ARTIFACTS, file.replace("/", "_").replace(".json", ".png"))
        driver.save_screenshot(shot)
        print(f"page: {file} → JSON and SVG shown; screenshot {shot}")
    # A refused request is shown as problem details.
    driver.execute_script("document.getElementById('request').value = '{\"no_such_field\": 1}'")
    driver.find_element(By.ID, "send").click()
    wait.until(lambda d: "422" in d.find_element(By.ID, "status").text)
    assert "/problems/" in driver.find_element(By.ID, "answer").text
    driver.save_screenshot(os.path.join(ARTIFACTS, "problem.png"))
    print("page: a refused request shows its problem details")
finally:
    driver.quit()
