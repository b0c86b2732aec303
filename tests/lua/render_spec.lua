-- render_spec.lua — outcrop.render from Lua: option checking, the default
-- camera, the three colour sources, AOVs against analytic answers, small
-- golden images, and what the written files carry.
--
-- Golden images live in tests/fixtures/render/ (EXR, half floats). After
-- an intended change of the renderer, regenerate them with
--   cd tests/lua && OUTCROP_REGEN_GOLDEN=1 OUTCROP_TEST_BUILD=... \
--     LUA_CPATH=... LUA_PATH=... busted --lua=lua5.4 render_spec.lua
-- (the spec then writes them instead of comparing), look at them
-- (e.g. `oiiotool golden.exr --colorconvert linear sRGB -o look.png`),
-- and commit them with the change.
local oc = require "outcrop"
require "helpers.gcstress" -- OUTCROP_GC_STRESS: eager collector
local Fs = require "helpers.files"
local read_file = Fs.read_file
local sh = Fs.sh
local info = Fs.image_info
local R = require "helpers.ref"

local F = "render_spec.lua"
local GOLDEN = "../fixtures/render/"
local regen = os.getenv("OUTCROP_REGEN_GOLDEN") == "1"

-- Radius of the surface f = T of a point primitive of radius R:
-- g(x) = (1 - x^2)^3 = T  =>  x = sqrt(1 - T^(1/3)).
local function iso_radius(r) return r * math.sqrt(1 - R.T ^ (1 / 3)) end




-- Mean and largest absolute difference between two images (all channels)
-- as idiff reports them.
local function compare(a, b)
  local out = sh("idiff -a '" .. a .. "' '" .. b .. "'")
  local mean = tonumber(out:match("Mean error = ([%d%.eE%-+]+)"))
  local max = tonumber(out:match("Max error%s+= ([%d%.eE%-+]+)"))
  -- within idiff's own threshold (1e-6) it says PASS and no figures
  if not mean and out:match("\nPASS") and not out:match("[Ee]rror") then
    mean, max = 0, 0
  end
  assert(mean and max, "idiff said: " .. out)
  return mean, max, out
end

-- A sphere (a point primitive) of radius r at c.
local function ball(c, r) return oc.point{center = c, radius = r} end

describe("outcrop.render", function()
  local sphere = ball({0, 0, 0}, 4)
  local rs = iso_radius(4)

  describe("checks its options", function()
    local cam = {eye = {0, -20, 0}, target = {0, 0, 0}}
    it("names the field and the line", function()
      R.check_error(function() oc.render(5) end, F, "outcrop.render", "argument #1 must be an outcrop node")
      R.check_error(function() oc.render(sphere, 5) end, F, "outcrop.render", "expected a table")
      R.check_error(function() oc.render(sphere, {sise = {4, 4}}) end, F, "outcrop.render", "unknown field 'sise'", "'size'")
      R.check_error(function() oc.render(sphere, {size = {0, 4}}) end, F, "outcrop.render", "'size'", "1..16384")
      R.check_error(function() oc.render(sphere, {size = {20000, 4}}) end, F, "outcrop.render", "'size'")
      R.check_error(function() oc.render(sphere, {size = {4.5, 4}}) end, F, "outcrop.render", "'size'")
      R.check_error(function() oc.render(sphere, {size = {4}}) end, F, "outcrop.render", "'size' must be {width, height}")
      R.check_error(function() oc.render(sphere, {camera = 3}) end, F, "outcrop.render", "'camera' must be a table")
      R.check_error(function() oc.render(sphere, {camera = {eye = {0, 1}}}) end, F, "outcrop.render", "camera.eye")
      R.check_error(function() oc.render(sphere, {camera = {eye = {0, 0 / 0, 1}}}) end, F, "outcrop.render", "camera.eye")
      R.check_error(function() oc.render(sphere, {camera = {fov = 0}}) end, F, "outcrop.render", "'camera.fov'")
      R.check_error(function() oc.render(sphere, {camera = {fov = 180}}) end, F, "outcrop.render", "'camera.fov'", "179")
      R.check_error(function() oc.render(sphere, {camera = {eyes = {1, 2, 3}}}) end, F, "outcrop.render", "unknown field 'camera.eyes'", "'camera.eye'")
      R.check_error(function() oc.render(sphere, {sun = {direction = {0, 0, 0}}}) end, F, "outcrop.render", "'sun.direction'")
      R.check_error(function() oc.render(sphere, {sun = {intensity = -1}}) end, F, "outcrop.render", "'sun.intensity'")
      R.check_error(function() oc.render(sphere, {sun = {radius = 0.5}}) end, F, "outcrop.render", "'sun.radius'", "[0, 0.1]")
      R.check_error(function() oc.render(sphere, {sun = {color = {1, 1}}}) end, F, "outcrop.render", "'sun.color' must be {r, g, b}")
      R.check_error(function() oc.render(sphere, {sky = {1, -1, 1}}) end, F, "outcrop.render", "'sky'", "(item 2 is -1)")
      R.check_error(function() oc.render(sphere, {sky = "blue"}) end, F, "outcrop.render", "'sky' must be {r, g, b}")
      R.check_error(function() oc.render(sphere, {background = {0, 0, 0, 2}}) end, F, "outcrop.render", "'background'", "(item 4 is 2)")
      R.check_error(function() oc.render(sphere, {background = {0, 0, 0, 0, 0}}) end, F, "outcrop.render", "'background' must be {r, g, b} or {r, g, b, a}")
      R.check_error(function() oc.render(sphere, {shadows = 1}) end, F, "outcrop.render", "'shadows' must be a boolean")
      R.check_error(function() oc.render(sphere, {ao = "yes"}) end, F, "outcrop.render", "'ao' must be a boolean")
      R.check_error(function() oc.render(sphere, {fog = -1}) end, F, "outcrop.render", "'fog'")
      R.check_error(function() oc.render(sphere, {fog = "thick"}) end, F, "outcrop.render", "'fog' must be a density")
      R.check_error(function() oc.render(sphere, {fog = {density = 0.1, distance = 5}}) end, F, "outcrop.render", "either 'fog.density' or 'fog.distance'")
      R.check_error(function() oc.render(sphere, {fog = {color = {1, 1, 1}}}) end, F, "outcrop.render", "missing field 'fog.density'")
      R.check_error(function() oc.render(sphere, {texture = 2}) end, F, "outcrop.render", "'texture'")
      R.check_error(function() oc.render(sphere, {threshold = 0}) end, F, "outcrop.render", "'threshold' must be a positive number")
      R.check_error(function() oc.render(sphere, {tracer = "fast"}) end, F, "outcrop.render", "'tracer' must be one of", "\"segment\"")
      R.check_error(function() oc.render(sphere, {aov = "Z"}) end, F, "outcrop.render", "'aov' must be a boolean")
      R.check_error(function() oc.render(sphere, {color = 3}) end, F, "outcrop.render", "'color' must be an outcrop node, a function")
      R.check_error(function() oc.render(sphere, {color = {palette = {}}}) end, F, "outcrop.render", "missing field 'color.field'")
      R.check_error(function() oc.render(sphere, {palette = {{0, {1, 1, 1}}}}) end, F, "outcrop.render", "'palette' maps a 'color' node")
      R.check_error(function() oc.render(sphere, {color = sphere, palette = {{0, {1, 2, 1}}}}) end, F, "outcrop.render", "'palette[1]' colour components must be in [0, 1]")
      R.check_error(function() oc.render(sphere, {color = sphere, palette = {{1, {1, 1, 1}}, {0, {0, 0, 0}}}}) end, F, "outcrop.render", "ascending")
      R.check_error(function() oc.render(sphere, {color = sphere, palette = {}}) end, F, "outcrop.render", "'palette' must be an array")
      R.check_error(function() oc.render(sphere, {color = {field = sphere, palette = {{0, {1}}}}}) end, F, "outcrop.render", "'color.palette[1]' colour must be {r, g, b}")
      R.check_error(function() oc.render(sphere, {color = sphere, rules = {}}) end, F, "outcrop.render", "'rules'", "cannot go with 'color'")
      R.check_error(function() oc.render(sphere, {rules = {sea_level = 5, snow_line = 1}}) end, F, "outcrop.render", "'rules.sea_level' must be below")
      R.check_error(function() oc.render(sphere, {rules = {rock_slope = 100}}) end, F, "outcrop.render", "'rules.rock_slope'")
      R.check_error(function() oc.render(sphere, {camera = cam}, 3) end, F, "outcrop.render")
    end)

    it("needs a camera when the bounds cannot give one", function()
      local ground = oc.plane{origin = {0, 0, 0}, normal = {0, 0, 1}}
      R.check_error(function() oc.render(ground, {size = {4, 4}}) end, F, "outcrop.render", "bounds are infinite", "'camera'")
      R.check_error(function() oc.render(ground, {size = {4, 4}, camera = {eye = {0, 0, 9}}}) end, F, "outcrop.render", "bounds are infinite")
      -- both given: no bounds needed
      local img = oc.render(ground, {size = {4, 4}, camera = {eye = {0, -10, 5}, target = {0, 0, 0}}})
      assert.are.equal(4, (img:size()))
    end)

    it("passes the engine's own refusals on with the line", function()
      -- a camera looking straight along its up vector
      R.check_error(function() oc.render(sphere, {size = {4, 4}, camera = {eye = {0, 0, 20}, target = {0, 0, 0}}}) end, F, "outcrop.render", "up")
      -- too many pixels, refused before anything is allocated
      R.check_error(function() oc.render(sphere, {size = {16384, 16384}}) end, F, "outcrop.render")
    end)
  end)

  it("frames the node's bounds by default", function()
    local img = oc.render(sphere, {size = {33, 25}, background = {0, 0, 0, 0}})
    local w, h = img:size()
    assert.are.equal(33, w)
    assert.are.equal(25, h)
    -- R, G, B, A and the AOVs by default
    assert.are.equal(12, img:channels())
    -- the centre pixel sees the ball, the border sees nothing
    assert.are.equal(1, select(4, img:get(17, 13)))
    for i = 1, w do
      assert.are.equal(0, select(4, img:get(i, 1)))
      assert.are.equal(0, select(4, img:get(i, h)))
    end
    for j = 1, h do
      assert.are.equal(0, select(4, img:get(1, j)))
      assert.are.equal(0, select(4, img:get(w, j)))
    end
  end)

  it("covers the analytic projected disc of a sphere", function()
    -- eye on the y axis at distance D, looking at the centre: the
    -- silhouette is a disc of angular radius asin(rs / D)
    local D, fov, n = 30, 40, 101
    local img = oc.render(sphere, {size = {n, n}, background = {0, 0, 0, 0},
      camera = {eye = {0, -D, 0}, target = {0, 0, 0}, fov = fov},
      shadows = false, ao = false})
    local hits = 0
    for j = 1, n do
      for i = 1, n do
        hits = hits + select(4, img:get(i, j))
      end
    end
    local rpix = math.tan(math.asin(rs / D)) / math.tan(math.rad(fov / 2)) * n / 2
    local disc = math.pi * rpix * rpix
    -- pixels are sampled at their centres: the count may be off by about
    -- the perimeter's worth of half pixels
    assert.is_true(math.abs(hits - disc) <= math.pi * rpix,
      string.format("%d pixels hit, disc of %.1f", hits, disc))
  end)

  describe("AOVs", function()
    local D, n = 25, 31
    local eye = {0, -D, 0}
    local img = oc.render(sphere, {size = {n, n}, aov = true, background = {0, 0, 0, 0},
      camera = {eye = eye, target = {0, 0, 0}, fov = 15}})

    it("has 12 channels", function()
      assert.are.equal(12, img:channels())
    end)

    it("gives depth, position and normal of the sphere #slowgc", function()
      -- footprint of a pixel at the sphere: the hit tolerance of the tracer
      local tol = 2 * D * math.tan(math.rad(7.5)) / n
      local c = {img:get(16, 16)} -- on the axis
      R.close(c[5], D - rs, tol, "Z on the axis")
      local checked = 0
      for j = 1, n do
        for i = 1, n do
          local v = {img:get(i, j)}
          if v[4] == 1 then
            local p = {v[9], v[10], v[11]}
            local nn = {v[6], v[7], v[8]}
            R.close(R.len(p), rs, tol, "hit on the sphere")
            R.close(R.len(R.sub(p, eye)), v[5], 1e-3 * D, "Z is the distance to P")
            -- the outward normal of a sphere is radial
            R.close(R.dot(nn, R.mul(p, 1 / R.len(p))), 1, 1e-2, "normal")
            assert.is_true(v[12] >= 1, "evals counted")
            checked = checked + 1
          else
            assert.are.equal(0, v[9]); assert.are.equal(0, v[6])
          end
        end
      end
      assert.is_true(checked > 150, checked .. " hits")
    end)

    it("are written to EXR under their names", function()
      local dir = R.tmpdir()
      assert.is_true(img:write(dir .. "/aov.exr"))
      local attrs, _, channels = info(dir .. "/aov.exr")
      -- (the order in the file is OpenEXR's, not the image's)
      local names = {}
      for c in channels:gmatch("[^, ]+") do names[#names + 1] = c end
      table.sort(names)
      assert.are.same({"A", "B", "G", "N.x", "N.y", "N.z", "P.x", "P.y", "P.z", "R", "Z", "evals"}, names)
      assert.are.equal(oc.version, attrs["outcrop:version"])
      -- PNG keeps the colour only
      assert.is_true(img:write(dir .. "/aov.png"))
      local a2, _, ch2 = info(dir .. "/aov.png")
      assert.are.equal("R, G, B, A", ch2)
      assert.are.equal(oc.version, a2["outcrop:version"])
      assert.are.equal("1", a2["outcrop:seed"])
      R.rmdir(dir)
    end)
  end)

  describe("AOVs by default", function()
    local cam = {eye = {0, -25, 3}, target = {0, 0, 0}, fov = 25}
    local plain = oc.render(sphere, {size = {20, 14}, camera = cam})
    local rgba = oc.render(sphere, {size = {20, 14}, camera = cam, aov = false})
    local with = oc.render(sphere, {size = {20, 14}, camera = cam, aov = true})

    it("do not change the colours #slowgc", function()
      assert.are.equal(12, plain:channels())
      assert.are.equal(4, rgba:channels())
      for j = 1, 14 do
        for i = 1, 20 do
          local a, b, c = {plain:get(i, j)}, {rgba:get(i, j)}, {with:get(i, j)}
          assert.are.same(b, {a[1], a[2], a[3], a[4]})
          assert.are.same(c, a)
        end
      end
    end)

    it("go to EXR files unless aov = false", function()
      local dir = R.tmpdir()
      local function names(path)
        local _, _, channels = info(path)
        local t = {}
        for c in channels:gmatch("[^, ]+") do t[#t + 1] = c end
        table.sort(t)
        return t
      end
      assert.is_true(plain:write(dir .. "/plain.exr"))
      assert.are.same({"A", "B", "G", "N.x", "N.y", "N.z", "P.x", "P.y", "P.z", "R", "Z", "evals"},
        names(dir .. "/plain.exr"))
      assert.is_true(rgba:write(dir .. "/rgba.exr"))
      assert.are.same({"A", "B", "G", "R"}, names(dir .. "/rgba.exr"))
      -- the same file as aov = true makes
      assert.is_true(with:write(dir .. "/with.exr"))
      assert.are.equal(read_file(dir .. "/with.exr"), read_file(dir .. "/plain.exr"))
      -- PNG and JPEG hold the colour only, the same bytes either way
      for _, ext in ipairs{"png", "jpg"} do
        assert.is_true(plain:write(dir .. "/plain." .. ext))
        assert.is_true(rgba:write(dir .. "/rgba." .. ext))
        assert.are.equal(read_file(dir .. "/rgba." .. ext), read_file(dir .. "/plain." .. ext))
      end
      R.rmdir(dir)
    end)
  end)

  describe("exposure and tone", function()
    local cam = {eye = {0, -25, 3}, target = {0, 0, 0}, fov = 25}
    local size = {16, 12}

    it("checks both fields", function()
      R.check_error(function() oc.render(sphere, {exposure = "bright"}) end, F, "outcrop.render", "'exposure' must be a number in [-20")
      R.check_error(function() oc.render(sphere, {exposure = 21}) end, F, "outcrop.render", "'exposure'")
      R.check_error(function() oc.render(sphere, {exposure = 0 / 0}) end, F, "outcrop.render", "'exposure'")
      R.check_error(function() oc.render(sphere, {tone = "aces"}) end, F, "outcrop.render", "'tone' must be one of", "\"filmic\"")
      R.check_error(function() oc.render(sphere, {tone = 1}) end, F, "outcrop.render", "'tone'")
    end)

    it("multiplies the colours by 2^exposure, alpha and AOVs kept #slowgc", function()
      local base = oc.render(sphere, {size = size, camera = cam})
      local up = oc.render(sphere, {size = size, camera = cam, exposure = 1.5})
      local zero = oc.render(sphere, {size = size, camera = cam, exposure = 0, tone = "clamp"})
      local k = 2 ^ 1.5
      for j = 1, 12 do
        for i = 1, 16 do
          local a, b = {base:get(i, j)}, {up:get(i, j)}
          for c = 1, 3 do R.close(b[c], a[c] * k, 1e-6 * (1 + a[c] * k)) end
          for c = 4, 12 do assert.are.equal(a[c], b[c]) end
          assert.are.same(a, {zero:get(i, j)})
        end
      end
    end)

    it("filmic: EXR keeps linear values, PNG goes through the curve", function()
      local dir = R.tmpdir()
      local img = oc.render(sphere, {size = size, camera = cam, exposure = 2, tone = "filmic"})
      local clamp = oc.render(sphere, {size = size, camera = cam, exposure = 2})
      -- the pixels are the same; only the written display values differ
      assert.are.same({clamp:get(8, 6)}, {img:get(8, 6)})
      assert.is_true(img:write(dir .. "/f.exr"))
      assert.is_true(clamp:write(dir .. "/c.exr"))
      local attrs = info(dir .. "/f.exr")
      assert.are.equal("filmic", attrs["outcrop:tone"])
      local mean = compare(dir .. "/f.exr", dir .. "/c.exr")
      assert.are.equal(0, mean)
      assert.is_true(img:write(dir .. "/f.png"))
      assert.is_true(clamp:write(dir .. "/c.png"))
      assert.are_not.equal(read_file(dir .. "/f.png"), read_file(dir .. "/c.png"))
      R.rmdir(dir)
    end)
  end)

  describe("colours", function()
    local scene = ball({0, 0, 2}, 3) + oc.box{min = {-8, -8, -3}, max = {8, 8, -1}, falloff = 1}
    local cam = {eye = {14, -18, 10}, target = {0, 0, 0}}

    it("calls a function once per hit pixel with position and normal", function()
      local calls, bad = 0, 0
      local img = oc.render(scene, {size = {24, 18}, camera = cam, background = {0, 0, 0, 0},
        color = function(x, y, z, nx, ny, nz)
          calls = calls + 1
          -- the point is on the surface, the normal a unit vector
          if math.abs(scene:eval(x, y, z) - R.T) > 0.05 then bad = bad + 1 end
          if math.abs(nx * nx + ny * ny + nz * nz - 1) > 1e-3 then bad = bad + 1 end
          return 1, 0, 0
        end})
      local hits = 0
      for j = 1, 18 do
        for i = 1, 24 do
          local r, g, b, a = img:get(i, j)
          if a == 1 then
            hits = hits + 1
            assert.is_true(r > 0)
            assert.are.equal(0, g); assert.are.equal(0, b)
          end
        end
      end
      assert.is_true(hits > 50)
      assert.are.equal(hits, calls)
      assert.are.equal(0, bad)
    end)

    it("reports errors of the function with its line", function()
      local f = function() error("no colour here") end
      local msg = R.error_of(function() oc.render(scene, {size = {4, 4}, camera = cam, color = f}) end)
      assert.is_truthy(msg:find(F .. ":%d+: no colour here"))
      R.check_error(function() oc.render(scene, {size = {4, 4}, camera = cam, color = function() return 1, 2, 0 end}) end, F, "outcrop.render", "must return r, g, b in [0, 1]", "g = 2")
      R.check_error(function() oc.render(scene, {size = {4, 4}, camera = cam, color = function() return 1 end}) end, F, "outcrop.render", "must return r, g, b", "g = nil")
    end)

    it("survives a function that recompiles the node", function()
      local img = oc.render(scene, {size = {8, 6}, camera = cam, color = function(x, y, z)
        oc.threshold = 0.3; scene:eval(x, y, z); oc.threshold = 0.5
        return 0.5, 0.5, 0.5
      end})
      assert.are.equal(8, (img:size()))
    end)

    it("maps a node through a palette #slowgc", function()
      local img = oc.render(scene, {size = {24, 18}, camera = cam, background = {0, 0, 0, 0},
        color = scene, palette = {{0, {0, 1, 0}}, {1, {0, 1, 0}}}})
      local same = oc.render(scene, {size = {24, 18}, camera = cam, background = {0, 0, 0, 0},
        color = {field = scene, palette = {{0, {0, 1, 0}}, {1, {0, 1, 0}}}}})
      local hits = 0
      for j = 1, 18 do
        for i = 1, 24 do
          local r, g, b, a = img:get(i, j)
          if a == 1 then
            hits = hits + 1
            assert.are.equal(0, r); assert.are.equal(0, b); assert.is_true(g > 0)
          end
          assert.are.same({img:get(i, j)}, {same:get(i, j)})
        end
      end
      assert.is_true(hits > 50)
      -- the default palette for a resistance in [0, 1]
      local strata = oc.render(scene, {size = {24, 18}, camera = cam, color = scene, aov = false})
      assert.are.equal(4, strata:channels())
    end)

    it("takes either rule level alone, deriving the other", function()
      -- every hit below a sea level of 100 m is sand; above a snow line of
      -- -100 m the flat top of the ground is snow: one level given, the
      -- other still derived (both used to be required)
      local function mean(img)
        local s, n = {0, 0, 0}, 0
        for j = 1, 18 do
          for i = 1, 24 do
            local r, g, b, a = img:get(i, j)
            if a == 1 then s[1], s[2], s[3], n = s[1] + r, s[2] + g, s[3] + b, n + 1 end
          end
        end
        return s[1] / n, s[2] / n, s[3] / n
      end
      local opt = function(rules)
        return {size = {24, 18}, camera = cam, background = {0, 0, 0, 0}, rules = rules}
      end
      local r0, g0, b0 = mean(oc.render(scene, opt(nil)))
      local rs, gs, bs = mean(oc.render(scene, opt({sea_level = 100})))
      local rw, gw, bw = mean(oc.render(scene, opt({snow_line = -100})))
      assert.is_true(rs > gs and gs > bs and rs > r0)     -- sand: warm
      assert.is_true(bw > b0 + 0.05 and gw > g0)          -- snow: white
      assert.are_not.same({r0, g0, b0}, {rs, gs, bs})
    end)

    it("accepts the rule parameters", function()
      local img = oc.render(scene, {size = {8, 6}, camera = cam,
        rules = {sea_level = -2, snow_line = 4, beach = 0.5, rock_slope = 40, snow_slope = 30}})
      assert.are.equal(8, (img:size()))
    end)
  end)

  it("applies background, fog and sky", function()
    local cam = {eye = {0, -30, 0}, target = {0, 0, 0}}
    local img = oc.render(sphere, {size = {9, 9}, camera = cam, background = {0.25, 0.5, 0.75, 0.5}, aov = false})
    assert.are.same({0.25, 0.5, 0.75, 0.5}, {img:get(1, 1)})
    -- the sky behind: its colour, lightened towards the horizon
    local sky = oc.render(sphere, {size = {9, 9}, camera = cam, sky = {0.1, 0.2, 0.3}})
    local r, g, b, a = sky:get(1, 1)
    assert.is_true(r >= 0.1 and g >= 0.2 and b >= 0.3 and b <= 1 and r < g and g < b)
    assert.are.equal(1, a)
    -- thick fog of the sky's colour hides the ball
    local fog = oc.render(sphere, {size = {9, 9}, camera = cam, sky = {0.1, 0.2, 0.3}, fog = {distance = 0.01}})
    r, g, b = fog:get(5, 5)
    R.close(r, 0.1, 1e-3); R.close(g, 0.2, 1e-3); R.close(b, 0.3, 1e-3)
    local fog2 = oc.render(sphere, {size = {9, 9}, camera = cam, fog = {density = 300, color = {1, 0, 0}}})
    r, g, b = fog2:get(5, 5)
    R.close(r, 1, 1e-3); R.close(g, 0, 1e-3); R.close(b, 0, 1e-3)
  end)

  it("stops at max_distance and takes the other tuning fields", function()
    local cam = {eye = {0, -30, 0}, target = {0, 0, 0}}
    local near = oc.render(sphere, {size = {9, 9}, camera = cam, aov = true, max_distance = 20})
    assert.are.equal(math.huge, select(5, near:get(5, 5)))
    local far = oc.render(sphere, {size = {9, 9}, camera = cam, aov = true, max_distance = 40,
      ao_distance = 0.5, texture = 0, texture_scale = 3, shadows = false, ao = false})
    R.close(select(5, far:get(5, 5)), 30 - rs, 0.1, "Z")
  end)

  it("traces the same surface with both tracers", function()
    local cam = {eye = {0, -30, 5}, target = {0, 0, 0}}
    local a = oc.render(sphere, {size = {16, 12}, camera = cam, aov = true, tracer = "segment"})
    local b = oc.render(sphere, {size = {16, 12}, camera = cam, aov = true, tracer = "sphere"})
    local differ, hits = 0, 0
    for j = 1, 12 do
      for i = 1, 16 do
        local va, vb = {a:get(i, j)}, {b:get(i, j)}
        -- (the sky's alpha is 1 too: a hit is a finite Z)
        local ha, hb = va[5] < math.huge, vb[5] < math.huge
        if ha ~= hb then differ = differ + 1 end
        if ha and hb then
          hits = hits + 1
          R.close(va[5], vb[5], 0.05, "Z")
        end
      end
    end
    assert.is_true(hits > 0)
    assert.is_true(differ <= 2, differ .. " pixels hit by one tracer only")
  end)

  it("traces an open terrain's side wall the same with both tracers #slowgc", function()
    -- rays climb through the corner where the wall x = 0 meets the top
    -- z = 10: under it they cross less solid than one sphere step
    local flat = oc.heightfield.from(function() return 10 end, {size = {41, 41}})
    local t = oc.terrain(flat, {falloff = 2})
    local cam = {eye = {-20, 20, 6}, target = {0, 20, 10}, fov = 10}
    local a = oc.render(t, {size = {64, 48}, camera = cam, aov = true, tracer = "segment"})
    local b = oc.render(t, {size = {64, 48}, camera = cam, aov = true, tracer = "sphere"})
    local differ, corner = 0, 0
    for j = 1, 48 do
      for i = 1, 64 do
        local va, vb = {a:get(i, j)}, {b:get(i, j)}
        local ha, hb = va[5] < math.huge, vb[5] < math.huge
        if ha ~= hb then differ = differ + 1 end
        if ha and hb then
          R.close(va[5], vb[5], 0.05, "Z")
          -- P.x, P.z: on the wall, in its top 0.25 m
          if va[9] < 0.01 and va[11] > 9.75 then corner = corner + 1 end
        end
      end
    end
    assert.is_true(corner >= 64, corner .. " hits at the corner")
    assert.is_true(differ <= 2, differ .. " pixels hit by one tracer only")
  end)

  it("is the same image when made twice", function()
    local cam = {eye = {5, -30, 5}, target = {0, 0, 0}}
    local dir = R.tmpdir()
    assert.is_true(oc.render(sphere, {size = {20, 10}, camera = cam, aov = true}):write(dir .. "/a.exr"))
    assert.is_true(oc.render(sphere, {size = {20, 10}, camera = cam, aov = true}):write(dir .. "/b.exr"))
    assert.are.equal(read_file(dir .. "/a.exr"), read_file(dir .. "/b.exr"))
    R.rmdir(dir)
  end)

  describe("golden images", function()
    local scene = ball({0, 0, 2}, 4) + oc.box{min = {-10, -10, -4}, max = {10, 10, -1}, falloff = 1}
    local cam = {eye = {16, -20, 12}, target = {0, 0, 0}, fov = 40}
    local cases = {
      -- (the goldens hold R, G, B, A: made before the AOVs were on by
      -- default; "AOVs by default" below checks that they are the same)
      {"sphere_plane", {size = {64, 48}, camera = cam, aov = false}},
      {"sphere_plane_function", {size = {64, 48}, camera = cam, aov = false,
        color = function(x, y, z, nx, ny, nz)
          -- bands of altitude, darker where steep
          local band = math.floor(z) % 2 == 0 and 0.8 or 0.4
          return band * (0.5 + 0.5 * nz * nz), 0.3, 0.6 - 0.2 * band
        end}},
    }
    for _, c in ipairs(cases) do
      it(c[1] .. " matches " .. c[1] .. ".exr", function()
        local golden = GOLDEN .. c[1] .. ".exr"
        local img = oc.render(scene, c[2])
        if regen then
          assert.is_true(img:write(golden))
          print("\nwrote " .. golden)
          return
        end
        assert.is_not_nil(read_file(golden), "missing " .. golden ..
          " (OUTCROP_REGEN_GOLDEN=1 writes it)")
        local dir = R.tmpdir()
        assert.is_true(img:write(dir .. "/now.exr"))
        local mean, max, out = compare(dir .. "/now.exr", golden)
        R.rmdir(dir)
        -- half floats store ~3 digits; rendering is deterministic, so
        -- anything beyond rounding is a change of the renderer
        assert.is_true(mean <= 2e-3, "mean difference " .. mean .. "\n" .. out)
        assert.is_true(max <= 0.05, "largest difference " .. max .. "\n" .. out)
      end)
    end
  end)
end)
