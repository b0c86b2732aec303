-- sample_spec.lua — outcrop.poisson2d and outcrop.poisson3d: separation
-- and maximality (checked here with a plain Lua bucket grid), determinism
-- by seed and the scene seed, the flat point set, thinning by a density
-- function or heightfield, a million points through the table path, and
-- every error with the script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "sample_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end

-- ---- a bucket grid of points, cells of side r ---------------------------

local function buckets(pts, r, d)
  local b = {}
  local function key(p)
    local k = math.floor(p[1] / r) .. ":" .. math.floor(p[2] / r)
    if d == 3 then k = k .. ":" .. math.floor(p[3] / r) end
    return k
  end
  for i, p in ipairs(pts) do
    local k = key(p)
    b[k] = b[k] or {}
    table.insert(b[k], i)
  end
  -- nearest distance from x to a point other than `skip`, within r
  return function(x, skip)
    local best = math.huge
    local cx, cy = math.floor(x[1] / r), math.floor(x[2] / r)
    local cz = d == 3 and math.floor(x[3] / r) or 0
    for dz = (d == 3 and -1 or 0), (d == 3 and 1 or 0) do
      for dy = -1, 1 do
        for dx = -1, 1 do
          local k = (cx + dx) .. ":" .. (cy + dy)
          if d == 3 then k = k .. ":" .. (cz + dz) end
          for _, i in ipairs(b[k] or {}) do
            if i ~= skip then
              local p, s = pts[i], 0
              for a = 1, d do s = s + (p[a] - x[a]) ^ 2 end
              best = math.min(best, math.sqrt(s))
            end
          end
        end
      end
    end
    return best
  end
end

local function check_set(pts, box, r, d, probes)
  local near = buckets(pts, r, d)
  local lo, hi = {}, {}
  for a = 1, d do lo[a], hi[a] = box[a], box[a + d] end
  local closest = math.huge
  for i, p in ipairs(pts) do
    assert.are.equal(d, #p)
    for a = 1, d do assert.is_true(p[a] >= lo[a] and p[a] <= hi[a]) end
    closest = math.min(closest, near(p, i))
  end
  assert.is_true(closest >= r * (1 - 1e-12), "two samples " .. closest .. " apart")
  -- maximal: random probes and the box's corners
  local rng = 12345
  local function unif()
    rng = (rng * 1103515245 + 12345) % 2147483648
    return rng / 2147483648
  end
  local gap = 0
  for _ = 1, probes do
    local x = {}
    for a = 1, d do x[a] = lo[a] + (hi[a] - lo[a]) * unif() end
    gap = math.max(gap, near(x))
  end
  for c = 0, 2 ^ d - 1 do
    local x = {}
    for a = 1, d do x[a] = (c >> (a - 1)) & 1 == 1 and hi[a] or lo[a] end
    gap = math.max(gap, near(x))
  end
  assert.is_true(gap <= r * (1 + 1e-9), "a point " .. gap .. " from every sample")
  -- the same probes see the hole a removed sample leaves
  local mid = #pts // 2
  local hole = near(pts[mid], mid)
  assert.is_true(hole > r)
  return closest, gap
end

-- ---- results -------------------------------------------------------------

describe("outcrop.poisson2d", function()
  local box, r = {-10, 5, 30, 25}, 1.5

  it("returns points at least r apart leaving no room for another", function()
    local pts = oc.poisson2d{box = box, radius = r, seed = 3}
    -- a maximal set holds about 0.70 points per r^2 (a little more along
    -- the box's edges)
    local per = #pts * r * r / (40 * 20)
    assert.is_true(per > 0.66 and per < 0.80, "density " .. per)
    check_set(pts, box, r, 2, 20000)
  end)

  it("is deterministic by seed, and the seed defaults to the scene seed", function()
    local a = oc.poisson2d{box = box, radius = r, seed = 8}
    local b = oc.poisson2d{box = box, radius = r, seed = 8}
    local c = oc.poisson2d{box = box, radius = r, seed = 9}
    local s = oc.poisson2d{box = box, radius = r}
    local one = oc.poisson2d{box = box, radius = r, seed = oc.seed}
    assert.are.same(a, b)
    assert.are_not.same(a, c)
    assert.are.same(one, s)
  end)

  it("returns a flat point set on request", function()
    local t = oc.poisson2d{box = box, radius = r, seed = 4}
    local p = oc.poisson2d{box = box, radius = r, seed = 4, flat = true}
    assert.are.equal(#t, #p)
    assert.are.equal(#t, p:count())
    assert.are.equal(2, p:dim())
    for i = 1, #t, 17 do
      local x, y = p:get(i)
      assert.are.equal(t[i][1], x)
      assert.are.equal(t[i][2], y)
    end
    assert.are.same(t, p:table())
    assert.matches("outcrop.points: %d+ points in 2D", tostring(p))
    check(function() p:get(0) end, "points:get", "1.." .. #t)
    check(function() p:get(#t + 1) end, "points:get", "(got " .. #t + 1 .. ")")
    do local q <close> = p end
    assert.matches("closed", tostring(p))
    assert.are.equal(0, #p)
    check(function() p:count() end, "points:count", "closed")
  end)

  it("thins by a density function, called once per sample in order", function()
    local full = oc.poisson2d{box = box, radius = r, seed = 5}
    local calls = {}
    local same = oc.poisson2d{box = box, radius = r, seed = 5, density = function(x, y)
      calls[#calls + 1] = {x, y}
      return 1
    end}
    assert.are.same(full, same)
    assert.are.same(full, calls)
    assert.are.equal(0, #oc.poisson2d{box = box, radius = r, seed = 5,
                                      density = function() return 0 end})
    -- 1 left of x = 10, 0.5 right of it: the left part untouched
    local half = oc.poisson2d{box = box, radius = r, seed = 5, density = function(x)
      return x < 10 and 1 or 0.5
    end}
    local nl, nr, hl, hr = 0, 0, 0, 0
    for _, p in ipairs(full) do if p[1] < 10 then nl = nl + 1 else nr = nr + 1 end end
    for _, p in ipairs(half) do if p[1] < 10 then hl = hl + 1 else hr = hr + 1 end end
    assert.are.equal(nl, hl)
    assert.is_true(math.abs(hr - nr / 2) <= 4 * math.sqrt(nr / 4), hr .. " of " .. nr)
  end)

  it("thins by a heightfield, its values clamped to [0, 1]", function()
    -- elevation 2 left of x = 10, -1 right of it
    local hf = oc.heightfield.from(function(x) return x < 10 and 2 or -1 end,
                                   {size = {41, 21}, cell = 1, origin = {-10, 5}})
    local full = oc.poisson2d{box = box, radius = r, seed = 6}
    local kept = oc.poisson2d{box = box, radius = r, seed = 6, density = hf}
    local left = 0
    for _, p in ipairs(full) do if p[1] < 8 then left = left + 1 end end
    local kl = 0
    for _, p in ipairs(kept) do
      assert.is_true(p[1] < 12, "kept at x = " .. p[1])
      if p[1] < 8 then kl = kl + 1 end
    end
    assert.are.equal(left, kl)
  end)

  it("handles a million points in the table path", function()
    local side = math.sqrt(1e6 / 0.697)
    local pts = oc.poisson2d{box = {0, 0, side, side}, radius = 1, seed = 1}
    assert.is_true(#pts > 0.98e6 and #pts < 1.03e6, tostring(#pts))
    local p = pts[#pts]
    assert.are.equal(2, #p)
    assert.is_true(p[1] >= 0 and p[1] <= side and p[2] >= 0 and p[2] <= side)
    pts = nil
    collectgarbage()
  end)
end)

describe("outcrop.poisson3d", function()
  it("returns points at least r apart leaving no room for another", function()
    local box, r = {0, -2, 1, 8, 6, 7}, 1.2
    local pts = oc.poisson3d{box = box, radius = r, seed = 2}
    local per = #pts * r ^ 3 / (8 * 8 * 6)
    -- (0.73 per r^3 far from the faces; this box is mostly near a face)
    assert.is_true(per > 0.73 and per < 1.1, "density " .. per)
    check_set(pts, box, r, 3, 20000)
    assert.are.same(pts, oc.poisson3d{box = box, radius = r, seed = 2})
    local p = oc.poisson3d{box = box, radius = r, seed = 2, flat = true}
    assert.are.equal(3, p:dim())
    assert.are.same({p:get(1)}, pts[1])
  end)
end)

-- ---- errors ----------------------------------------------------------------

describe("poisson errors", function()
  local P2, P3 = "outcrop.poisson2d", "outcrop.poisson3d"
  it("names the field and the script line", function()
    check(function() oc.poisson2d() end, P2)
    check(function() oc.poisson2d{radius = 1} end, P2, "'box'")
    check(function() oc.poisson2d{box = {0, 0, 1}, radius = 1} end, P2, "'box'", "{x0, y0, x1, y1}")
    check(function() oc.poisson2d{box = {0, 0, 0 / 0, 1}, radius = 1} end, P2, "'box'")
    check(function() oc.poisson2d{box = {0, 0, math.huge, 1}, radius = 1} end, P2, "'box'")
    check(function() oc.poisson2d{box = {1, 0, 0, 1}, radius = 1} end, P2, "'box'", "x0 < x1")
    check(function() oc.poisson2d{box = {0, 0, 1, 1}} end, P2, "'radius'")
    check(function() oc.poisson2d{box = {0, 0, 1, 1}, radius = -1} end, P2, "'radius'")
    check(function() oc.poisson2d{box = {0, 0, 1, 1}, radius = 0 / 0} end, P2, "'radius'")
    check(function() oc.poisson2d{box = {0, 0, 1, 1}, radius = math.huge} end, P2, "'radius'")
    check(function() oc.poisson2d{box = {0, 0, 1, 1}, radius = 1, seed = -1} end, P2, "'seed'")
    check(function() oc.poisson2d{box = {0, 0, 1, 1}, radius = 1, raduis = 1} end, P2, "'raduis'")
    check(function() oc.poisson2d{box = {0, 0, 1, 1}, radius = 1, density = 3} end,
      P2, "'density'", "function")
    check(function() oc.poisson2d{box = {0, 0, 1, 1}, radius = 1, flat = 1} end, P2, "'flat'")
    check(function() oc.poisson3d{box = {0, 0, 0, 1, 1, 1}, radius = 1, density = 1} end,
      P3, "'density'")
    check(function() oc.poisson3d{box = {0, 0, 1, 1}, radius = 1} end, P3, "'box'")
  end)

  it("refuses absurd counts before allocating", function()
    check(function() oc.poisson2d{box = {0, 0, 1e4, 1e4}, radius = 1e-3} end,
      P2, "'radius'", "50 million")
    check(function() oc.poisson3d{box = {0, 0, 0, 1e3, 1e3, 1e3}, radius = 0.5} end,
      P3, "'radius'", "50 million")
  end)

  it("reports bad density values and passes the function's errors on", function()
    local box = {0, 0, 5, 5}
    check(function() oc.poisson2d{box = box, radius = 1, density = function() return 2 end} end,
      P2, "'density'", "[0, 1]", "got 2")
    check(function() oc.poisson2d{box = box, radius = 1, density = function() return "x" end} end,
      P2, "'density'", "[0, 1]")
    check(function() oc.poisson2d{box = box, radius = 1, density = function() return 0 / 0 end} end,
      P2, "'density'")
    local ok, msg = pcall(oc.poisson2d, {box = box, radius = 1, density = function()
      error("boom")
    end})
    assert.is_false(ok)
    assert.matches("sample_spec.lua:%d+: boom", msg)
    local ok2, obj = pcall(oc.poisson2d, {box = box, radius = 1, density = function()
      error({code = 7})
    end})
    assert.is_false(ok2)
    assert.are.equal(7, obj.code)
  end)
end)
