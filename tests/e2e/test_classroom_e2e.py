

def test_a_horde_of_800_demons_keeps_the_table_small_searchable_and_summarised(
    browser: Browser, server: RunningServer
) -> None:
    count = 800
    demons = [
        {"name": f"d{i:03d}", "policy": "uniform", "cumulant": 1, "learner": "td", "discount": 0.9}
        for i in range(count)
    ]
    body = {"scenario": "experiment1", "seed": 1, "name": "horde", "behaviour": "uniform", "demons": demons}
    response = server.client.post("/api/runs", params={"hz": 20, "start": True}, json=body)
    assert response.status_code == 201, response.text
    run_id = response.json()["id"]
    page, errors = new_page(browser, 1440, 900, TOUR_DONE)
    select(page, server, run_id)
    summary = page.get_by_test_id("demon-summary")
    summary.filter(has_text=f"{count} demons · {count} learning · 0 diverged").wait_for()
    rows = page.locator("table.demon-table tbody tr[data-demon]")
    assert 0 < rows.count() < 60, "only the rows in sight (and a few more) exist"
    # Scrolled to the end, the last demons are there (and the first are gone).
    page.locator(".table-scroll.virtual").evaluate("box => box.scrollTo(0, box.scrollHeight)")
    page.locator('table.demon-table tr[data-demon="d799"]').wait_for()
    assert page.locator('table.demon-table tr[data-demon="d000"]').count() == 0
    # The search finds one demon among 800; its predictions come from the stream's turns.
    page.get_by_label("Find demons").fill("d417")
    page.locator('table.demon-table tr[data-demon="d417"]').wait_for()
    assert rows.count() == 1
    # The overview shows every prediction; the charts only the chosen ones (12 by default).
    assert page.locator("section.overview canvas").is_visible()
    assert page.locator(".chart").count() == 12
    server.client.post(f"/api/runs/{run_id}/pause")
    assert errors == []
    page.context.close()
