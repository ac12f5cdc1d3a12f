import { defineConfig } from "vitest/config";

// `npm run dev` serves the dashboard with hot reload and forwards /api (REST and the WebSocket
// streams) to a `horde serve` on port 8000; `npm run build` writes frontend/dist for FastAPI to serve.
export default defineConfig({
  server: {
    proxy: {
      "/api": { target: "http://127.0.0.1:8000", ws: true },
    },
  },
  build: {
    outDir: "dist",
    emptyOutDir: true,
    // The server serves dist/assets at /assets (backend/horde/server/frontend.py).
    assetsDir: "assets",
  },
  test: {
    include: ["tests/**/*.test.ts"],
    environment: "node",
  },
});
