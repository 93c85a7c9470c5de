// `gltf-transform --config js/gltf-transform-animorder/gltf-transform.config.js prune in.glb out.glb`:
// the CLI reads, keeps and writes ANIMORDER_animated_triangle_orders.
import { AnimorderTriangleOrders } from './index.js';

export default { extensions: [AnimorderTriangleOrders] };
